#pragma once
// The smallest signed gap over the body-body and self-contact pairs active in a state (the
// run CSV's and the panel's min_gap, with the planes' and obstacles'). Measured on the
// host from positions, independently of the solver's contact stage: for each node the
// stage flagged in contact this step, the boundary triangles it may touch (another body's;
// its own, except those it is a corner of, with self-contact) whose plane it lies within the contact
// tolerance of, with its projection inside the triangle and (another body's) facing a
// triangle around the node (body_contact.h, faces_some); the gap is its signed distance from that plane
// (negative: inside).
#include <cstdint>
#include <vector>

#include "sim/contact/body_contact_tables.h"

namespace softtled {

// x: positions, 3 per node (interleaved); contact: nnode ContactState. +infinity when no
// flagged node is within the tolerance of such a triangle.
double min_body_gap(const BodyContactTables& t, const std::vector<double>& x, const std::vector<std::uint8_t>& contact,
                    bool bodies, bool self);

}  // namespace softtled
