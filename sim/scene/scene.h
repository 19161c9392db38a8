#pragma once
// Scene description (TOML). Every key is documented in README.md ("Scene format");
// unknown keys, wrong types and out-of-range values are InputErrors naming the key.
// Named modes are parsed into their enums here, once; *_name() gives the name back.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "sim/io/output_file.h"
#include "sim/mesh/tetgen_mesher.h"
#include "sim/solver/solver.h"

namespace softtled {

// The most bodies a scene may hold ([[body]] tables). Body-body contact tests every pair
// of bodies' bounding boxes each step (B^2 / 2 tests), the CSV has 3 columns per body and
// every body is meshed by its own TetGen run at start-up; 32 keeps all three small.
constexpr int kMaxBodies = 32;
constexpr int kMaxTrackPoints = 1000;  // output.track_points: 3 CSV columns each

// One body: today's body.* keys, and optionally its own [body.material].
struct BodyDesc {
  std::string key = "body";     // how messages name it: "body" ([body]) or "body[i]" ([[body]])
  std::string shape = "torus";  // torus | box | sphere | file
  std::string file;             // surface file for shape = "file"
  double major_radius = 7.5, tube_radius = 2.5;  // torus [units]
  std::array<int, 2> segments = {91, 19};
  std::array<double, 3> size = {10, 10, 10};     // box [units]
  std::array<int, 3> divisions = {4, 4, 4};
  double radius = 5.0;                           // sphere [units]
  int subdivisions = 3;                          // sphere: icosahedron subdivisions
  double scale = 1.0;                            // applied to a loaded file
  std::array<double, 3> position = {0, 0, 0};    // [units]
  std::array<double, 3> rotation_deg = {0, 0, 0};  // about x, then y, then z
  std::array<double, 3> velocity = {0, 0, 0};    // [m/s]
  // [body.material]: this body's own E, rho, nu, model and element; unset (E, rho < 0,
  // nu < -1, model or element < 0): the scene's [material], live. In a one-body scene
  // parse_scene makes them the scene's [material] and leaves these unset.
  double own_E = -1, own_rho = -1, own_nu = -2;
  int own_model = -1;    // MaterialModel
  int own_element = -1;  // ElementType
  // Whether it sets its own nu, model or element (a law of its own: element_law.h).
  bool own_law() const { return own_nu > -2 || own_model >= 0 || own_element >= 0; }
};

// Physical ranges of the material, motion and contact keys (scene file and live changes
// alike). Each is far outside any soft body a user can mean, and inside what the step and
// its float32 state can represent; a value past one is a typo or a unit slip, refused with
// the key's name rather than run into a frozen body, a NaN or a silently meaningless answer.
constexpr double kMaxYoungsModulus = 1e12;  // Pa: diamond is 1.2e12
constexpr double kMaxDensity = 1e5;         // kg/m^3: osmium is 2.3e4
constexpr double kMaxAlpha = 1e6;           // 1/s: alpha dt > 2 already over-damps a 2 us step
constexpr double kMaxBeta = 1.0;            // s: beta >= dt_cr shrinks the step below dt_cr / 2
constexpr double kMaxGravity = 1e6;         // m/s^2 per component: 1e5 g (the crush test uses 2000 g)
constexpr double kMaxSpeed = 1e4;           // m/s per component: 30x the speed of sound in air
constexpr double kMaxRotationDeg = 1e6;     // per rotation_deg component: beyond, the angle's
                                            // reduction mod 360 loses its degrees
constexpr double kMaxMu = 1e3;              // friction coefficient: above ~10 Coulomb is static anyway
constexpr double kMaxDuration = 1e7;        // s of simulated time
// Poisson's ratio nu lies in the open interval (kMinPoisson, kMaxPoisson): 0.5 is
// incompressible (lambda infinite), -1 has no bulk stiffness (K = 0).
constexpr double kMinPoisson = -1.0;
constexpr double kMaxPoisson = 0.5;

// Body 0's keys are the Scene's own (a one-body scene reads and edits them as before);
// bodies 1.. are in more_bodies.
struct Scene : BodyDesc {
  std::string source;      // file it came from (messages, relative paths)
  double length_unit = 1e-3;  // metres per scene length unit ("mm" by default)

  // [[body]] tables after the first (the first is the BodyDesc base)
  std::vector<BodyDesc> more_bodies;
  int body_count() const { return 1 + int(more_bodies.size()); }
  const BodyDesc& body(int i) const { return i == 0 ? static_cast<const BodyDesc&>(*this) : more_bodies[i - 1]; }
  BodyDesc& body(int i) { return i == 0 ? static_cast<BodyDesc&>(*this) : more_bodies[i - 1]; }
  double body_E(int i) const { return body(i).own_E > 0 ? body(i).own_E : E; }
  double body_rho(int i) const { return body(i).own_rho > 0 ? body(i).own_rho : rho; }
  double body_nu(int i) const { return body(i).own_nu > -1 ? body(i).own_nu : nu; }
  int body_model(int i) const { return body(i).own_model >= 0 ? body(i).own_model : int(material_model); }
  int body_element(int i) const { return body(i).own_element >= 0 ? body(i).own_element : int(element); }
  // Whether some body sets its own nu, model or element.
  bool per_body_law() const;
  // Whether body-body contact runs: contact.bodies (default: true) and >= 2 bodies.
  bool body_contact() const { return contact_bodies && body_count() >= 2; }

  // [mesh]  (TetGen)
  TetgenOptions tetgen;        // max_volume here in [units^3]

  // [material]
  MaterialModel material_model = kTaylorNeoHookean;  // neo_hookean | stable_neo_hookean
  ElementType element = kT4;                         // T4 | T4ANP
  double E = 3000, nu = 0.49, rho = 1000;  // [Pa, -, kg/m^3]

  // [damping]
  double alpha = 10;  // [1/s]
  double beta = 0;    // stiffness-proportional (Rayleigh) damping [s]; 0 = off

  // [gravity]
  std::array<double, 3> g = {0, -9.81, 0};

  // [floor]
  bool floor = true;
  std::array<double, 3> floor_point = {0, -12, 0};  // [units]
  std::array<double, 3> floor_normal = {0, 1, 0};

  // [slope]: the floor turned by angle_deg about z through slope.point
  bool slope = false;
  double slope_angle_deg = 20;
  std::array<double, 3> slope_point = {0, -12, 0};

  // [contact]
  ContactMode contact_mode = kSliding;  // sliding | static | coulomb
  double mu = 0.5;
  std::string contact_nodes = "boundary";  // boundary | all
  bool contact_bodies = true;  // body-body contact (with >= 2 bodies)
  bool contact_self = false;   // self-contact of each body (body_contact.h)

  // [time]
  bool dt_auto = true;
  bool dt_adaptive = false;  // time.dt = "adaptive": dt = lambda * 2 / omega_max(live state)
  double dt = 0;        // [s] when neither auto nor adaptive
  double dt_max = 1e300;  // [s] cap of the adaptive step
  double lambda = 0.5;  // dt = lambda * dt_cr for auto and adaptive
  bool allow_unstable = false;  // run a fixed dt above dt_cr (the watchdog still stops divergence)
  double duration = 0.2;
  double output_every = 1e-3;

  // [solver]
  Precision precision = Precision::kDouble;  // float | double
  int threads = 0;                   // 0: OpenMP default

  // [[fixed]]: nodes held at their rest position, selected by boxes or planes.
  struct FixedSelector {
    bool is_box = true;
    std::array<double, 3> a{}, b{};  // box: min, max corners; plane: point, normal [units]
  };
  std::vector<FixedSelector> fixed;

  // [[obstacle]]: rigid obstacles (at most kMaxObstacles), in scene units. Which keys a
  // shape takes: sphere center, radius; box center, size, rotation_deg; capsule a, b,
  // radius; mesh file, center, scale, rotation_deg, resolution; each optionally velocity [m/s].
  struct ObstacleDesc {
    ObstacleShape shape = kObstacleSphere;
    std::array<double, 3> center{}, size{}, rotation_deg{}, a{}, b{}, velocity{};
    double radius = 0;
    std::string file;         // mesh: closed surface file (OBJ, OFF, STL), relative to the scene file
    double scale = 1;         // mesh: applied to the file's coordinates (then units)
    int resolution = kDefaultSdfResolution;  // mesh: distance grid cells across its longest side
  };
  std::vector<ObstacleDesc> obstacles;

  bool mesh_cache = true;  // [mesh] cache: reuse a TetGen result for the same surface + switches

  // [output]
  std::vector<std::array<double, 3>> track_points;  // rest positions [units]; nearest node is tracked
};

// Parses TOML text. overrides are "dotted.key=value" strings applied before validation;
// a value that is not valid TOML is taken as a string (contact.mode=sliding).
// surface (`mesh --surface F`): F replaces the scene's bodies as one file body (body 0's
// position, scale, material... stay); overrides of body.shape, body.file, another shape's
// keys or a body other than 0 are refused, since they would do nothing.
Scene parse_scene(const std::string& toml_text, const std::string& source,
                  const std::vector<std::string>& overrides = {}, const std::string& surface = "");
// Scene files larger than this are refused before they are read; scene text (parse_scene)
// larger than this is refused too.
constexpr std::uint64_t kMaxSceneBytes = 4ull << 20;
// Reads a regular file of at most kMaxSceneBytes (read_input_file); errors name the path
// and the OS reason ("scene file PATH: cannot open file: No such file or directory").
// Why a law with law_has_negative_energy (neo_hookean.h) is refused, for messages.
std::string negative_energy_law_why();

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {},
                 const std::string& surface = "");

// The files a scene reads, for check_distinct_paths (no output may overwrite one): the
// scene file itself (as `scene_flag`, when it came from a file), every body's file
// (relative to the scene's folder; a TetGen .node/.ele body both halves) and every mesh
// obstacle's file.
std::vector<PathUse> scene_inputs(const Scene& s, const std::string& scene_flag);
// check_distinct_paths of one output against scene_inputs(s, scene_flag).
void check_not_scene_input(const Scene& s, const std::string& scene_flag, const PathUse& output);

// The scene file's names of the modes.
const char* material_model_name(MaterialModel m);
const char* element_name(ElementType e);
const char* contact_mode_name(ContactMode m);
const char* precision_name(Precision p);
const char* obstacle_shape_name(ObstacleShape s);

}  // namespace softtled
