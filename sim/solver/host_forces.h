#pragma once
// Internal nodal forces of a whole body on the host, in double, through the same element
// stages and gather as the solvers (for the static check and the time-step estimate).
#include <vector>

#include "sim/fem/element_law.h"
#include "sim/fem/neo_hookean.h"
#include "sim/solver/rest_state.h"

namespace softtled {

// u: 3 x nnode SoA displacement; f: 3 x nnode SoA internal force. element: ElementType.
// laws: one per body where r has per-body laws (element_law.h), else empty.
void host_internal_forces(const RestArrays<double>& r, const NeoHookean<double>& mat, int element,
                          const std::vector<double>& u, std::vector<double>& f,
                          const std::vector<ElementLaw<double>>& laws = {});

}  // namespace softtled
