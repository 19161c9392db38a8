#pragma once
// The app's bridge between a Simulation and render/ (which knows no sim type): the body's
// vertex buffer and its per-frame fill, the planes and obstacles as plain geometry, and a camera and
// plane size that frame the body. The viewer and the offscreen frames share these.
#include <memory>
#include <string>
#include <vector>

#include "render/body_buffer.h"
#include "render/camera.h"
#include "render/scene_renderer.h"
#include "render/render_input_error.h"
#include "render/shader.h"
#include "sim/core/input_error.h"
#include "sim/mesh/surface_topology.h"
#include "sim/scene/simulation.h"

namespace softtled {

// A vertex buffer for the boundary the simulation writes: build_surface_topology(mesh)
// gives the vertex and triangle order the solver uses.
std::unique_ptr<BodyVertexBuffer> make_body_buffer(const SurfaceTopology& topo);
// The per-frame hand-off: the simulation writes its render vertices straight into the
// mapped buffer (a device pointer on a GPU backend, host memory otherwise), their colour
// scalar the one `color` maps (von Mises for ColorMode::kVonMises, else |u|). On a GPU
// backend this waits for the queued steps.
void write_body_vertices(Simulation& sim, BodyVertexBuffer& body, ColorMode color);

std::vector<RenderPlane> render_planes(const std::vector<PlaneSpec>& planes);
std::vector<RenderObstacle> render_obstacles(const std::vector<ObstacleSpec>& obstacles);

// make() (what builds shader programs or a GL context) with a render setting of the
// user's that cannot be used (render/render_input_error.h) thrown as InputError: exit 2.
template <class Make>
auto with_render_input_errors(Make&& make) -> decltype(make()) {
  try {
    return make();
  } catch (const RenderInputError& e) {
    throw InputError(e.what());
  }
}

// The legend of the colour map `style` uses, in plain numbers for render/: for |u| the
// range the body shader maps, 0 .. style.umax, in mm ("displacement [mm]", "magnitude,
// turbo"); for von Mises 0 .. style.vmmax in kPa ("von Mises [kPa]", "Cauchy, turbo");
// for the contact map its three states; none when shaded.
ColorLegend color_legend(const RenderStyle& style);

// The colour maps' names as --color, render_png's color= and the viewer's log spell them,
// indexed by ColorMode: "shaded", "displacement", "contact", "von_mises".
const std::vector<std::string>& color_mode_names();
const std::string& color_mode_name(ColorMode c);
// One of color_mode_names(); anything else is an InputError naming the option (`option`:
// how the caller's user spells it, e.g. "--color").
ColorMode parse_color_mode(const std::string& name, const std::string& option);

// Camera that frames the body's rest shape and the floor below it, seen slightly from above.
Camera default_camera(const Simulation& sim);
// Half side of the drawn planes [m]: a few body sizes.
float default_plane_half(const Simulation& sim);

}  // namespace softtled
