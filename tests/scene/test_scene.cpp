// Scene files: defaults equal the paper's scene, overrides by dotted key, and every kind
// of bad input names the offending key.
#include <gtest/gtest.h>

#include "scene_helpers.h"
#include "sim/scene/scene.h"
#include "sim/scene/scene_geometry.h"
#include "sim/mesh/surface_mesh.h"

using namespace softtled;
using namespace softtled::test;

namespace {
std::string error_of(const std::string& toml, const std::vector<std::string>& set = {}) {
  try {
    parse_scene(toml, "s.toml", set);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(Scene, ShippedScenesParse) {
  for (const char* f : {"torus_drop.toml", "torus_slope_static.toml", "torus_slope_sliding.toml"}) {
    const Scene s = load_scene(assets_dir() + "/scenes/" + f);
    EXPECT_DOUBLE_EQ(s.E, 3000.0) << f;
    EXPECT_DOUBLE_EQ(s.nu, 0.49) << f;
  }
  const Scene st = load_scene(assets_dir() + "/scenes/torus_slope_static.toml");
  EXPECT_TRUE(st.slope);
  EXPECT_EQ(st.contact_mode, kStatic);
}

// The slope turns the floor about z: with the floor's normal along z (z up) no angle tilts
// it, and a body dropped there rested unmoved with no word of why. Refused, naming the key;
// a y-up floor, a flat slope and a z-up floor without a slope still load.
TEST(Scene, ASlopeThatCannotTiltIsRefused) {
  const std::vector<std::string> zup = {"gravity.g=[0, 0, -9.81]", "floor.normal=[0, 0, 1]", "slope.enabled=true"};
  try {
    parse_scene("", "z.toml", zup);
    FAIL() << "a z-up slope loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("slope.angle_deg"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("floor.normal is along z"), std::string::npos) << e.what();
  }
  std::vector<std::string> flat = zup;
  flat.push_back("slope.angle_deg=0");
  EXPECT_NO_THROW(parse_scene("", "z.toml", flat));
  EXPECT_NO_THROW(parse_scene("", "z.toml", {"floor.normal=[0, 0, 1]", "slope.angle_deg=30"}));  // no slope
  EXPECT_NO_THROW(parse_scene("", "y.toml", {"slope.enabled=true", "slope.angle_deg=30"}));
  // A floor normal mostly along z is tilted by a fraction of the angle: refused too, naming
  // the tilt (a probe's [0, 1e-6, 1] at 89 degrees ran as a flat floor).
  for (const char* n : {"floor.normal=[0.1, 0, 1]", "floor.normal=[0, 1e-6, 1]"})
    try {
      parse_scene("", "t.toml", {"gravity.g=[0, 0, -9.81]", n, "slope.enabled=true", "slope.angle_deg=30"});
      ADD_FAILURE() << n << ": loaded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("30 degrees tilts it by only"), std::string::npos) << e.what();
    }
  // A floor tilted a little from y up keeps most of the angle (29.6 of 30 degrees).
  EXPECT_NO_THROW(parse_scene("", "t.toml", {"floor.normal=[0, 1, 0.2]", "slope.enabled=true", "slope.angle_deg=30"}));
}

TEST(Scene, ObstacleLengthsHaveAFloorButAMeshScaleIsAFactor) {
  // Radii and box sides below 1e-6 m are refused (a subnormal radius ran as an obstacle of
  // no size); a mesh obstacle's scale is a factor, not a length: 0.0005 in a mm scene is
  // fine (its scaled size is checked when the file is read).
  const std::string head = "units = \"mm\"\n[[obstacle]]\n";
  try {
    parse_scene(head + "shape = \"sphere\"\ncenter = [0, -30, 0]\nradius = 1e-4\n", "s.toml");
    FAIL() << "a 0.1 um sphere loaded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("obstacle[0].radius: value 0.0001 is below 1e-6 m"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(parse_scene(head + "shape = \"sphere\"\ncenter = [0, -30, 0]\nradius = 1e-3\n", "s.toml"));
  EXPECT_NO_THROW(parse_scene(head + "shape = \"mesh\"\nfile = \"big.obj\"\nscale = 0.0005\n", "m.toml"));
}

TEST(Scene, OverridesByDottedKey) {
  const Scene s = parse_scene("", "s", {"material.E=5000", "contact.mode=coulomb", "slope.angle_deg=30",
                                        "slope.enabled=true", "time.dt=2e-6", "body.segments=[45, 9]"});
  EXPECT_DOUBLE_EQ(s.E, 5000);
  EXPECT_EQ(s.contact_mode, kCoulomb);
  EXPECT_DOUBLE_EQ(s.slope_angle_deg, 30);
  EXPECT_TRUE(s.slope);
  EXPECT_FALSE(s.dt_auto);
  EXPECT_DOUBLE_EQ(s.dt, 2e-6);
  EXPECT_EQ(s.segments[0], 45);
}

TEST(Scene, NamedModesParseToTheirEnumsAndBack) {
  const Scene s = parse_scene("", "s", {"material.model=stable_neo_hookean", "contact.mode=static",
                                        "solver.precision=float"});
  EXPECT_EQ(s.material_model, kStableNeoHookean);
  EXPECT_EQ(s.contact_mode, kStatic);
  EXPECT_EQ(s.precision, Precision::kFloat);
  EXPECT_STREQ(material_model_name(s.material_model), "stable_neo_hookean");
  EXPECT_STREQ(contact_mode_name(s.contact_mode), "static");
  EXPECT_STREQ(precision_name(s.precision), "float");
  const Scene d = parse_scene("", "s", {"material.element=T4ANP"});
  EXPECT_EQ(d.element, kT4ANP);
  EXPECT_STREQ(element_name(d.element), "T4ANP");
  EXPECT_EQ(d.material_model, kTaylorNeoHookean) << "defaults";
  EXPECT_EQ(d.contact_mode, kSliding);
  EXPECT_EQ(d.precision, Precision::kDouble);
}

TEST(Scene, BadInputNamesTheKey) {
  EXPECT_NE(error_of("[material]\nEE = 3\n").find("material.EE: unknown key"), std::string::npos);
  EXPECT_NE(error_of("colour = 3\n").find("colour: unknown key"), std::string::npos);
  EXPECT_NE(error_of("[[material]]\nE = 3000\n").find("material: [[material]] repeats a table; only [[body]], [[obstacle]] and [[fixed]] may repeat"),
            std::string::npos)
      << error_of("[[material]]\nE = 3000\n");
  EXPECT_NE(error_of("[output]\ntrack_points = [[1e30, 0, 0]]\n").find("output.track_points: element 0 lies beyond 10000 m"),
            std::string::npos);
  // A user's value is quoted shortened: a 3 MB string made a 3 MB message.
  const std::string huge = error_of("units = \"" + std::string(3 << 20, 'm') + "\"\n");
  EXPECT_LT(huge.size(), 400u);
  EXPECT_NE(huge.find("...' (3145728 characters) is not one of: m, mm"), std::string::npos) << huge.substr(0, 400);
  // UTF-8 text is shown as it is (it read '????'); control characters and broken UTF-8 are '?'.
  EXPECT_NE(error_of("units = \"\u043c\u043c\"\n").find("'\u043c\u043c' is not one of"), std::string::npos)
      << error_of("units = \"\u043c\u043c\"\n");
  EXPECT_EQ(quoted(std::string("a\x01\xff\xd0") + "b"), "'a???b'");
  EXPECT_NE(error_of("", {"material.E=nan"}).find("material.E: must be finite"), std::string::npos);
  EXPECT_NE(error_of("[material]\nE = -5.0\n").find("material.E: value -5 out of range"), std::string::npos);
  EXPECT_NE(error_of("[material]\nnu = 0.5\n").find("material.nu"), std::string::npos);
  EXPECT_NE(error_of("[material]\nrho = 0\n").find("material.rho"), std::string::npos);
  // A positive quantity that is subnormal underflows to 0 at once (nodes of no mass).
  for (const char* set : {"material.rho=4.9e-324", "material.E=1e-320", "time.output_every=5e-324"})
    EXPECT_NE(error_of("", {set}).find("is subnormal"), std::string::npos) << set << ": " << error_of("", {set});
  EXPECT_NE(error_of("[time]\ndt = 0.0\n").find("time.dt"), std::string::npos);
  EXPECT_NE(error_of("[contact]\nmode = \"sticky\"\n").find("contact.mode: 'sticky' is not one of"), std::string::npos);
  EXPECT_NE(error_of("[body]\nsize = [1, 2]\n").find("body.size: expected an array of 3"), std::string::npos);
  EXPECT_NE(error_of("[body\n").find("s.toml:1"), std::string::npos);
  EXPECT_NE(error_of("[body]\nshape = \"file\"\n").find("body.file: required"), std::string::npos);
  EXPECT_NE(error_of("", {"novalue"}).find("expected key=value"), std::string::npos);
  try {
    load_scene("/nonexistent/scene.toml");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene file /nonexistent/scene.toml: cannot open file: No such file or directory"),
              std::string::npos)
        << e.what();
  }
  // Scene files go through the same reader as surfaces: regular files only, size-capped.
  for (const char* p : {"/tmp", "/dev/null"}) {
    try {
      load_scene(p);
      ADD_FAILURE() << p;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("scene file ") + p + ": not a regular file"), std::string::npos)
          << e.what();
    }
  }
}

// The mesh.* keys: ranges of the switch grammar, the budget keys, key-named messages.
TEST(Scene, MeshKeys) {
  auto error_of = [](const std::string& toml) {
    try {
      parse_scene(toml, "s.toml");
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  const Scene s = parse_scene("[mesh]\nmax_tets = 1234\ntime_limit_s = 5\nradius_edge = 1.1\nmin_dihedral_deg = 0.001\n", "s.toml");
  EXPECT_EQ(s.tetgen.max_tets, 1234);
  EXPECT_EQ(s.tetgen.time_limit_s, 5);
  EXPECT_EQ(scene_tetgen_options(s).max_tets, 1234);
  EXPECT_EQ(scene_tetgen_options(s).time_limit_s, 5);
  EXPECT_NE(error_of("[mesh]\nmax_tets = 0\n").find("s.toml: mesh.max_tets: value out of range"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\nmax_tets = 1e9\n").find("s.toml: mesh.max_tets: expected an integer"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\nmax_tets = 300000000\n").find("mesh.max_tets: value out of range"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\ntime_limit_s = -1\n").find("s.toml: mesh.time_limit_s: value -1 out of range"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\ntime_limit_s = nan\n").find("mesh.time_limit_s: must be finite"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\nradius_edge = 1.05\n").find("s.toml: mesh.radius_edge: must be 0"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\nradius_edge = 1001\n").find("mesh.radius_edge: value 1001 out of range"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\nmin_dihedral_deg = 0.0005\n").find("s.toml: mesh.min_dihedral_deg: must be 0"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\nmin_dihedral_deg = 21\n").find("mesh.min_dihedral_deg: value 21 out of range"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\nswitches = \"" + std::string(1500, 'q') + "\"\n").find("s.toml: mesh.switches: at most 64"),
            std::string::npos);
  EXPECT_NE(error_of("[mesh]\nswitches = \"pT1\"\n").find("s.toml: mesh.switches: 'T' is not supported"), std::string::npos);
  EXPECT_NE(error_of("[mesh]\nmax_volume = inf\n").find("mesh.max_volume: must be finite"), std::string::npos);
  // A bound that underflows on the way to m^3 (or to TetGen's mm^3) is not "no bound"
  // (it meshed without one), nor may it reach TetGen (a subnormal "a" crashed it).
  EXPECT_NE(error_of("[mesh]\nmax_volume = 5e-324\n").find("s.toml: mesh.max_volume: must be 0 (no bound) or"),
            std::string::npos);
  EXPECT_NE(error_of("[mesh]\nmax_volume = 1e-308\n").find("mesh.max_volume: 1e-317 m^3 is below the smallest bound"),
            std::string::npos);
  EXPECT_NE(error_of("[mesh]\nswitches = \"pa1e-320\"\n").find("mesh.switches: 'a1e-320': the volume bound must be"),
            std::string::npos);
  // The stable model below its Poisson bound (neo_hookean.h kMinStableNeoHookeanNu): its
  // energy has negative states there, scene-wide or in a body's own material.
  EXPECT_NE(error_of("[material]\nmodel = \"stable_neo_hookean\"\nnu = -0.95\n").find("material.nu: the stable_neo_hookean energy"),
            std::string::npos);
  EXPECT_EQ(error_of("[material]\nmodel = \"stable_neo_hookean\"\nnu = -0.88\n"), "no error");
  EXPECT_EQ(error_of("[material]\nnu = -0.95\n"), "no error");
  const std::string two = "[[body]]\nposition = [0, 10, 0]\n[[body]]\nposition = [0, 40, 0]\n[body.material]\n";
  EXPECT_NE(error_of(two + "model = \"stable_neo_hookean\"\nnu = -0.95\n").find("body[1].material: the stable_neo_hookean"),
            std::string::npos) << error_of(two + "model = \"stable_neo_hookean\"\nnu = -0.95\n");
  EXPECT_EQ(error_of(two + "model = \"stable_neo_hookean\"\nnu = -0.8\n"), "no error");
  // A bound just past its limit is shown as given, not rounded onto the limit ("got 20").
  EXPECT_NE(error_of("[mesh]\nswitches = \"pq1.1/20.0000001\"\n").find("got 20.0000001"), std::string::npos)
      << error_of("[mesh]\nswitches = \"pq1.1/20.0000001\"\n");
  // The switches replace the quality keys: both given, the keys were dropped silently.
  for (const char* k : {"radius_edge = 1.2", "min_dihedral_deg = 5.0", "max_volume = 0.01", "keep_boundary = true"})
    EXPECT_NE(error_of(std::string("[mesh]\nswitches = \"pq2\"\n") + k + "\n").find("mesh.switches: replaces mesh."),
              std::string::npos)
        << k;
  EXPECT_EQ(error_of("[mesh]\nswitches = \"pq2\"\n"), "no error");
}

// scene_surface names the keys that put a surface out of TetGen's range.
TEST(Scene, SurfaceErrorsNameTheKeys) {
  auto error_of = [](const std::string& toml) {
    try {
      scene_surface(parse_scene(toml, "s.toml"));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  // An angle of 1e300 degrees is no orientation (its reduction mod 360 has no digits left):
  // bounded as the obstacles' are.
  EXPECT_NE(error_of("[body]\nrotation_deg = [0, 1e300, 0]\n").find("body.rotation_deg: element 1 = 1e+300 is out of range [-1e+06, 1e+06]"),
            std::string::npos);
  EXPECT_NE(error_of("[body]\nposition = [1e15, 0, 0]\n").find("s.toml: body.position/body.rotation_deg: surface to mesh"),
            std::string::npos);
  EXPECT_NE(error_of("[body]\nshape = \"sphere\"\nradius = 1e-200\n").find("s.toml: body.radius/body.subdivisions"),
            std::string::npos);
  EXPECT_NE(error_of("[body]\nsegments = [4096, 4096]\n").find("s.toml: body.major_radius/body.tube_radius/body.segments"),
            std::string::npos);
  EXPECT_NE(error_of("[body]\nshape = \"file\"\nfile = \"/tmp\"\n").find("s.toml: body.file: /tmp: not a regular file"),
            std::string::npos);
  EXPECT_EQ(error_of("[body]\nshape = \"box\"\n"), "no error");
}

TEST(Scene, ObstaclesParseInMetresWithTheirShapeKeys) {
  const Scene s = parse_scene(
      "[[obstacle]]\nshape = \"sphere\"\ncenter = [1, 2, 3]\nradius = 4\n"
      "[[obstacle]]\nshape = \"box\"\ncenter = [0, -5, 0]\nsize = [10, 2, 6]\nrotation_deg = [0, 0, 90]\nvelocity = [0.1, 0, 0]\n"
      "[[obstacle]]\nshape = \"capsule\"\na = [0, 0, 0]\nb = [0, 0, 8]\nradius = 1.5\n",
      "s");
  ASSERT_EQ(s.obstacles.size(), 3u);
  EXPECT_EQ(s.obstacles[0].shape, kObstacleSphere);
  EXPECT_EQ(s.obstacles[1].shape, kObstacleBox);
  EXPECT_EQ(s.obstacles[2].shape, kObstacleCapsule);
  EXPECT_STREQ(obstacle_shape_name(s.obstacles[2].shape), "capsule");
  const std::vector<ObstacleSpec> o = scene_obstacles(s);  // mm -> m
  EXPECT_DOUBLE_EQ(o[0].center[2], 3e-3);
  EXPECT_DOUBLE_EQ(o[0].radius, 4e-3);
  EXPECT_DOUBLE_EQ(o[1].half[0], 5e-3);
  EXPECT_DOUBLE_EQ(o[1].velocity[0], 0.1) << "velocities in m/s";
  EXPECT_TRUE(o[1].moving());
  EXPECT_FALSE(o[0].moving());
  // Turned 90 degrees about z: the box's 10 mm side lies along y.
  const double above[3] = {0, -5e-3 + 6e-3, 0};
  EXPECT_NEAR(signed_distance(o[1], above), 1e-3, 1e-12);
  EXPECT_DOUBLE_EQ(o[2].b[2], 8e-3);
  const double beside[3] = {3e-3, 0, 4e-3};
  EXPECT_NEAR(signed_distance(o[2], beside), 1.5e-3, 1e-15);
}

TEST(Scene, BadObstaclesNameTheKey) {
  const std::string sphere = "[[obstacle]]\nshape = \"sphere\"\ncenter = [0, 0, 0]\n";
  EXPECT_NE(error_of("[[obstacle]]\nshape = \"cone\"\n").find("obstacle[0].shape: 'cone' is not one of: sphere, box, capsule, mesh"), std::string::npos);
  // shape = "mesh": the keys parse_scene checks (the file itself is read at start-up,
  // tests/scene/test_mesh_obstacle.cpp).
  const std::string mesh = "[[obstacle]]\nshape = \"mesh\"\n";
  EXPECT_NE(error_of(mesh).find("obstacle[0].file: required for a mesh obstacle"), std::string::npos);
  EXPECT_NE(error_of(mesh + "file = 3\n").find("obstacle[0].file: expected a file name"), std::string::npos);
  EXPECT_NE(error_of(mesh + "file = \"a.obj\"\nresolution = 500\n").find("obstacle[0].resolution: value 500 out of range [8, 120]"),
            std::string::npos);
  EXPECT_NE(error_of(mesh + "file = \"a.obj\"\nresolution = 4\n").find("obstacle[0].resolution: value 4 out of range"),
            std::string::npos);
  EXPECT_NE(error_of(mesh + "file = \"a.obj\"\nresolution = 32.5\n").find("obstacle[0].resolution: expected an integer"),
            std::string::npos);
  EXPECT_NE(error_of(mesh + "file = \"a.obj\"\nscale = 0\n").find("obstacle[0].scale: must be positive, got 0"),
            std::string::npos);
  EXPECT_NE(error_of(mesh + "file = \"a.obj\"\nscale = nan\n").find("obstacle[0].scale: must be finite"), std::string::npos);
  EXPECT_NE(error_of(mesh + "file = \"a.obj\"\nradius = 1\n").find("obstacle[0].radius: unknown key (a mesh obstacle takes"),
            std::string::npos);
  {
    const Scene m = parse_scene(mesh + "file = \"bowl.obj\"\ncenter = [1, 2, 3]\nscale = 2\nrotation_deg = [0, 90, 0]\n"
                                       "resolution = 40\nvelocity = [0, 0.1, 0]\n",
                                "s");
    ASSERT_EQ(m.obstacles.size(), 1u);
    EXPECT_EQ(m.obstacles[0].shape, kObstacleMesh);
    EXPECT_STREQ(obstacle_shape_name(m.obstacles[0].shape), "mesh");
    EXPECT_EQ(m.obstacles[0].file, "bowl.obj");
    EXPECT_EQ(m.obstacles[0].scale, 2.0);
    EXPECT_EQ(m.obstacles[0].resolution, 40);
    EXPECT_EQ(m.obstacles[0].center[2], 3.0);
    EXPECT_EQ(m.obstacles[0].rotation_deg[1], 90.0);
    EXPECT_EQ(m.obstacles[0].velocity[1], 0.1);
    EXPECT_EQ(parse_scene(mesh + "file = \"bowl.obj\"\n", "s").obstacles[0].resolution, kDefaultSdfResolution);
  }
  EXPECT_NE(error_of("[[obstacle]]\ncenter = [0, 0, 0]\n").find("obstacle[0].shape: required"), std::string::npos);
  EXPECT_NE(error_of(sphere).find("obstacle[0].radius: required for a sphere obstacle"), std::string::npos);
  EXPECT_NE(error_of(sphere + "radius = nan\n").find("obstacle[0].radius: must be finite"), std::string::npos);
  EXPECT_NE(error_of(sphere + "radius = -1\n").find("obstacle[0].radius: must be positive, got -1"), std::string::npos);
  EXPECT_NE(error_of(sphere + "radius = 0\n").find("obstacle[0].radius: must be positive, got 0"), std::string::npos);
  EXPECT_NE(error_of(sphere + "radius = 1\nsize = [1, 1, 1]\n").find("obstacle[0].size: unknown key (a sphere obstacle takes"),
            std::string::npos);
  EXPECT_NE(error_of(sphere + "radius = 1\ncolour = \"red\"\n").find("obstacle[0].colour: unknown key"), std::string::npos);
  EXPECT_NE(error_of("[[obstacle]]\nshape = \"box\"\ncenter = [0, 0, 0]\nsize = [1, -2, 1]\n").find("obstacle[0].size: element 1 must be positive"),
            std::string::npos);
  EXPECT_NE(error_of("[[obstacle]]\nshape = \"box\"\ncenter = [0, nan, 0]\nsize = [1, 2, 1]\n").find("obstacle[0].center: element 1 is not a finite number"),
            std::string::npos);
  EXPECT_NE(error_of("[[obstacle]]\nshape = \"box\"\ncenter = [0, 0, 0]\n").find("obstacle[0].size: required for a box obstacle"), std::string::npos);
  EXPECT_NE(error_of("[[obstacle]]\nshape = \"capsule\"\na = [0, 0, 0]\nradius = 1\n").find("obstacle[0].b: required for a capsule obstacle"),
            std::string::npos);
  EXPECT_NE(error_of(sphere + "radius = 1\nvelocity = [1e5, 0, 0]\n").find("obstacle[0].velocity: element 0 = 100000 is out of range"),
            std::string::npos);
  // Just past the limit: shown in the digits that tell it from the limit.
  const std::string past = error_of("[[obstacle]]\nshape = \"box\"\ncenter = [0, -9, 0]\nsize = [1, 1, 1]\n"
                                    "rotation_deg = [1000000.1, 0, 0]\n");
  EXPECT_NE(past.find("obstacle[0].rotation_deg: element 0 = 1000000.1 is out of range [-1e+06, 1e+06]"), std::string::npos)
      << past;
  std::string nine;
  for (int i = 0; i < kMaxObstacles + 1; ++i) nine += sphere + "radius = 1\n";
  EXPECT_NE(error_of(nine).find("obstacle: at most 8 obstacles, got 9"), std::string::npos);
  EXPECT_NE(error_of("obstacle = 3\n").find("obstacle: expected [[obstacle]] tables"), std::string::npos);
}

TEST(Scene, SetAddressesObstaclesByIndex) {
  const std::string two = "[[obstacle]]\nshape = \"sphere\"\ncenter = [0, -8, 0]\nradius = 3\n"
                          "[[obstacle]]\nshape = \"box\"\ncenter = [20, -8, 0]\nsize = [4, 4, 4]\n";
  const Scene s = parse_scene(two, "s.toml", {"obstacle.0.center=[5, -9, 1]", "obstacle.1.velocity=[0, 0.5, 0]",
                                              "obstacle.1.rotation_deg=[0, 45, 0]"});
  ASSERT_EQ(s.obstacles.size(), 2u);
  EXPECT_EQ(s.obstacles[0].center, (std::array<double, 3>{5, -9, 1}));
  EXPECT_EQ(s.obstacles[0].radius, 3) << "keys not set keep the file's values";
  EXPECT_EQ(s.obstacles[1].center, (std::array<double, 3>{20, -8, 0}));
  EXPECT_EQ(s.obstacles[1].velocity, (std::array<double, 3>{0, 0.5, 0}));
  EXPECT_EQ(s.obstacles[1].rotation_deg, (std::array<double, 3>{0, 45, 0}));
  // The moved obstacle is where the geometry puts it (scene units to metres).
  EXPECT_DOUBLE_EQ(scene_obstacles(s)[0].center[0], 5e-3);
  // A set value goes through the same checks as the file's own.
  EXPECT_NE(error_of(two, {"obstacle.0.radius=-2"}).find("obstacle[0].radius: must be positive, got -2"), std::string::npos);
  EXPECT_NE(error_of(two, {"obstacle.1.size=[1, 0, 1]"}).find("obstacle[1].size: element 1 must be positive"), std::string::npos);
  // Changing the shape asks for that shape's keys.
  EXPECT_NE(error_of(two, {"obstacle.0.shape=box"}).find("obstacle[0].radius: unknown key (a box obstacle takes"),
            std::string::npos);
}

TEST(Scene, BadObstacleSetNamesTheKey) {
  const std::string one = "[[obstacle]]\nshape = \"sphere\"\ncenter = [0, -8, 0]\nradius = 3\n";
  // An index past the last obstacle, and a scene without [[obstacle]] tables.
  EXPECT_NE(error_of(one, {"obstacle.1.center=[0, 0, 0]"}).find("--set obstacle.1.center: the scene has no obstacle 1 (it has 1"),
            std::string::npos);
  EXPECT_NE(error_of("", {"obstacle.0.center=[0, 0, 0]"}).find("--set obstacle.0.center: the scene has no [[obstacle]] tables"),
            std::string::npos);
  // No index, a bad index, a nested key.
  for (const std::string bad : {"obstacle.center=[0, 0, 0]", "obstacle.x.center=[0, 0, 0]", "obstacle.-1.center=[0, 0, 0]",
                                "obstacle.0=[0, 0, 0]", "obstacle.0.center.x=1", "obstacle.1234.radius=1",
                                "obstacle.00.radius=1"}) {
    const std::string e = error_of(one, {bad});
    EXPECT_NE(e.find("--set '" + bad + "': obstacle keys are 'obstacle.N.key'"), std::string::npos) << bad << ": " << e;
  }
  // An unknown key is named with its obstacle, as in the file.
  EXPECT_NE(error_of(one, {"obstacle.0.colour=red"}).find("obstacle[0].colour: unknown key (a sphere obstacle takes"),
            std::string::npos);
  EXPECT_NE(error_of(one, {"obstacle.0.size=[1, 1, 1]"}).find("obstacle[0].size: unknown key"), std::string::npos);
}

// Dotted keys of thousands of parts overflow toml++'s recursion: they are refused by the
// scanner first, in a file, inside [body], and in a --set value; strings and comments are
// not keys, and floats or the scene's own keys pass.
TEST(Scene, DeepDottedKeysAreRefusedBeforeParsing) {
  auto chain = [](int n) {
    std::string k = "a";
    for (int i = 1; i < n; ++i) k += ".a";
    return k;
  };
  const std::string deep = chain(40000);
  EXPECT_NE(error_of(deep + " = 1\n").find("s.toml:1: key 'a.a.a"), std::string::npos);
  EXPECT_NE(error_of(deep + " = 1\n").find("has more than 32 dotted parts"), std::string::npos);
  EXPECT_NE(error_of("[body]\n" + deep + " = 1\n").find("s.toml:2: key 'a.a"), std::string::npos);
  EXPECT_NE(error_of("[" + deep + "]\n").find("more than 32 dotted parts"), std::string::npos);
  EXPECT_NE(error_of("\"a\" . " + chain(40) + " = 1\n").find("more than 32 dotted parts"), std::string::npos);
  EXPECT_NE(error_of("", {"material.E={" + deep + "=1}"}).find("--set material.E:1: key 'a.a"), std::string::npos);
  // 32 parts reach toml++ (and are then an unknown key); in strings and comments, dots are text.
  EXPECT_NE(error_of(chain(32) + " = 1\n").find("s.toml: a.a: unknown key"), std::string::npos);
  const std::string dots(5000, '.');
  EXPECT_EQ(error_of("# " + dots + "\n[body]\nshape = \"file\"\nfile = \"" + dots + ".obj\"\n"), "");
  EXPECT_EQ(error_of("[output]\ntrack_points = [[1.5, 2.5, 3.5]] # a.b\n"), "");
  EXPECT_EQ(error_of("[mesh]\nswitches = '''\n" + dots + "'''\n").find("more than 32"), std::string::npos);
  EXPECT_EQ(error_of("[mesh]\nswitches = \"\"\"\n\\\"" + dots + "\"\"\"\n").find("more than 32"), std::string::npos);
}

// A quoted key with a dot is one key of that name: unknown, not the dotted path.
TEST(Scene, QuotedDottedKeysAreUnknown) {
  EXPECT_NE(error_of("\"time.duration\" = -5\n").find("s.toml: time.duration: unknown key: a quoted key containing '.'"),
            std::string::npos);
  EXPECT_NE(error_of("\"material.E\" = 1e30\n").find("material.E: unknown key: a quoted key"), std::string::npos);
  EXPECT_NE(error_of("\"floor.enabled\" = \"yes\"\n").find("floor.enabled: unknown key: a quoted key"), std::string::npos);
  EXPECT_NE(error_of("[time]\n\"a.b\" = 1\n").find("time.\"a.b\": unknown key: a quoted key"), std::string::npos);
  EXPECT_NE(error_of("[body]\n\"material.E\" = 1e30\n").find("body.\"material.E\": unknown key: a quoted key"),
            std::string::npos);
  EXPECT_NE(error_of("[[body]]\n[[body]]\n\"material.E\" = 1e30\n").find("body[1].\"material.E\": unknown key"),
            std::string::npos);
  EXPECT_NE(error_of("[body.material]\n\"E.x\" = 1\n").find("body.material.E.x: unknown key"), std::string::npos);
}

// --set sets leaf keys: never a whole section (added, removed or replaced tables).
TEST(Scene, SetRefusesSectionsAndTrailingContent) {
  const std::string one = "[[obstacle]]\nshape = \"sphere\"\ncenter = [0, -8, 0]\nradius = 3\n";
  EXPECT_NE(error_of("", {"obstacle=[{shape=\"sphere\", center=[0,0,0], radius=1}]"})
                .find("--set obstacle: 'obstacle' is a section, not a key: set its keys one by one (--set obstacle.N.key=value)"),
            std::string::npos);
  EXPECT_NE(error_of(one, {"obstacle=[]"}).find("--set obstacle: 'obstacle' is a section"), std::string::npos);
  EXPECT_NE(error_of("", {"material={E=5}"})
                .find("--set material: 'material' is a section, not a key: set its keys one by one (--set material.key=value)"),
            std::string::npos);
  EXPECT_NE(error_of("", {"material=5"}).find("--set material: 'material' is a section"), std::string::npos);
  EXPECT_NE(error_of("", {"fixed=[]"}).find("--set fixed: 'fixed' is a section"), std::string::npos);
  EXPECT_NE(error_of("", {"material.E={a=1}"}).find("--set material.E: a table value is not accepted"), std::string::npos);
  EXPECT_NE(error_of("", {"body.material={E=5}"}).find("--set body.material: a table value is not accepted"),
            std::string::npos);
  EXPECT_NE(error_of("", {"body.material=5"}).find("--set body.material: 'material' is a table, not a key"),
            std::string::npos);
  EXPECT_NE(error_of("", {"body.0.material=5"}).find("--set body.0.material: 'material' is a table, not a key"),
            std::string::npos);
  // The file's other material keys survive a set one.
  const Scene s = parse_scene("[material]\nE = 4000\nnu = 0.3\nrho = 900\n", "s.toml", {"material.E=5"});
  EXPECT_DOUBLE_EQ(s.E, 5);
  EXPECT_DOUBLE_EQ(s.nu, 0.3);
  EXPECT_DOUBLE_EQ(s.rho, 900);
  // Anything after the value.
  EXPECT_NE(error_of("", {"material.E=3000\nmaterial.nu=0.1"}).find("--set material.E: the value must be on one line"),
            std::string::npos);
  EXPECT_NE(error_of("", {"material.E=3000\rx"}).find("--set material.E: the value must be on one line"), std::string::npos);
  EXPECT_DOUBLE_EQ(parse_scene("", "s", {"material.E=3000 # a comment"}).E, 3000);
  // A bad body index is named as one.
  EXPECT_NE(error_of("", {"body.-1.position=[0, 0, 0]"}).find("--set 'body.-1.position=[0, 0, 0]': the body index '-1' is invalid"),
            std::string::npos);
  EXPECT_NE(error_of("", {"body.x.position=[0, 0, 0]"}).find("the body index 'x' is invalid"), std::string::npos);
}

TEST(Scene, TimeKeysNameTheirProblem) {
  EXPECT_NE(error_of("", {"time.duration=0"}).find("s.toml: time.duration: value 0 out of range (0, "), std::string::npos);
  EXPECT_NE(error_of("", {"damping.alpha=1000000.1"}).find("damping.alpha: value 1000000.1 out of range [0, 1e+06]"),
            std::string::npos)
      << error_of("", {"damping.alpha=1000000.1"});
  EXPECT_NE(error_of("", {"time.dt=\"Auto\""})
                .find("time.dt: expected a step in seconds, \"auto\" or \"adaptive\" (lower case), got 'Auto'"),
            std::string::npos);
  EXPECT_NE(error_of("", {"time.dt=true"}).find("time.dt: expected a step in seconds, \"auto\" or \"adaptive\""),
            std::string::npos);
  EXPECT_NE(error_of("", {"time.dt_max=1e-5"}).find("time.dt_max: applies only with time.dt = \"adaptive\" (here time.dt is \"auto\")"),
            std::string::npos);
  EXPECT_NE(error_of("", {"time.dt=1e-6", "time.dt_max=1e-5"}).find("time.dt_max: applies only with time.dt = \"adaptive\" (here time.dt is a fixed step)"),
            std::string::npos);
  const Scene s = parse_scene("", "s", {"time.dt=adaptive", "time.dt_max=1e-5"});
  EXPECT_TRUE(s.dt_adaptive);
  EXPECT_DOUBLE_EQ(s.dt_max, 1e-5);
}

TEST(Scene, FixedSelectorsAreOneKindAndTyped) {
  const std::string both = "[[fixed]]\nbox_min = [0, 0, 0]\nbox_max = [1, 1, 1]\nplane_point = [0, 0, 0]\nplane_normal = [0, 1, 0]\n";
  EXPECT_NE(error_of(both).find("s.toml: fixed[0].plane_point: cannot be combined with box_min/box_max"), std::string::npos);
  EXPECT_NE(error_of("[[fixed]]\nbox_min = \"x\"\nplane_point = [0, 0, 0]\nplane_normal = [0, 1, 0]\n")
                .find("fixed[0].plane_point: cannot be combined"),
            std::string::npos);
  EXPECT_NE(error_of("[[fixed]]\nbox_min = \"x\"\nbox_max = [1, 1, 1]\n").find("fixed[0].box_min: expected an array of 3 numbers"),
            std::string::npos);
  EXPECT_NE(error_of("[[fixed]]\nplane_point = [0, 0, 0]\nplane_normal = 5\n").find("fixed[0].plane_normal: expected an array of 3"),
            std::string::npos);
  EXPECT_NE(error_of("[[fixed]]\nbox_max = [1, 1, 1]\n").find("fixed[0].box_min: required with box_max"), std::string::npos);
  EXPECT_NE(error_of("[[fixed]]\nbox_min = [1, 1, 1]\n").find("fixed[0].box_max: required with box_min"), std::string::npos);
  EXPECT_NE(error_of("[[fixed]]\nplane_normal = [0, 1, 0]\n").find("fixed[0].plane_point: required with plane_normal"),
            std::string::npos);
  const Scene s = parse_scene("[[fixed]]\nplane_point = [0, 0, 0]\nplane_normal = [0, 2, 0]\n", "s");
  ASSERT_EQ(s.fixed.size(), 1u);
  EXPECT_FALSE(s.fixed[0].is_box);
  EXPECT_DOUBLE_EQ(s.fixed[0].b[1], 1);
}

TEST(Scene, SetAddressesFixedRegionsByIndex) {
  // [[fixed]] tables took no --set ("keys are 'section.key' or 'key'"): now fixed.N.key,
  // as obstacles, with the file's checks.
  const std::string two = "[[fixed]]\nbox_min = [-1, -1, -1]\nbox_max = [1, 1, 1]\n"
                          "[[fixed]]\nplane_point = [0, 0, 0]\nplane_normal = [1, 0, 0]\n";
  const Scene s = parse_scene(two, "s.toml", {"fixed.0.box_max=[2, 3, 4]", "fixed.1.plane_point=[5, 0, 0]"});
  ASSERT_EQ(s.fixed.size(), 2u);
  EXPECT_EQ(s.fixed[0].b, (std::array<double, 3>{2, 3, 4}));
  EXPECT_EQ(s.fixed[0].a, (std::array<double, 3>{-1, -1, -1})) << "keys not set keep the file's values";
  EXPECT_EQ(s.fixed[1].a, (std::array<double, 3>{5, 0, 0}));
  EXPECT_NE(error_of(two, {"fixed.2.box_max=[1, 1, 1]"}).find("--set fixed.2.box_max: the scene has no fixed 2 (it has 2"),
            std::string::npos);
  EXPECT_NE(error_of("", {"fixed.0.box_max=[1, 1, 1]"}).find("the scene has no [[fixed]] tables"), std::string::npos);
  // An inverted box is named as such (it was "fixed[0] selects no node" once meshed).
  EXPECT_NE(error_of(two, {"fixed.0.box_min=[0, 5, 0]", "fixed.0.box_max=[1, 1, 1]"})
                .find("fixed[0].box_min: exceeds box_max along y: the box is empty"),
            std::string::npos)
      << error_of(two, {"fixed.0.box_min=[0, 5, 0]", "fixed.0.box_max=[1, 1, 1]"});
  const std::string e = error_of(two, {"fixed.box_max=[1, 1, 1]"});
  EXPECT_NE(e.find("fixed keys are 'fixed.N.key'"), std::string::npos) << e;
  EXPECT_NE(error_of(two, {"fixed.0.colour=red"}).find("fixed[0].colour"), std::string::npos) << error_of(two, {"fixed.0.colour=red"});
}

// Tracked points: at most kMaxTrackPoints, none twice (each costs three CSV columns).
TEST(Scene, TrackPointsAreLimitedAndDistinct) {
  std::string many = "[output]\ntrack_points = [";
  for (int i = 0; i <= kMaxTrackPoints; ++i) many += (i ? ", [" : "[") + std::to_string(i * 1e-3) + ", 0, 0]";
  EXPECT_NE(error_of(many + "]\n").find("output.track_points: 1001 points, at most 1000"), std::string::npos);
  EXPECT_NE(error_of("[output]\ntrack_points = [[0, 1, 0], [0, 2, 0], [0, 1, 0]]\n").find("element 2 repeats an earlier point"),
            std::string::npos);
  EXPECT_EQ(error_of("[output]\ntrack_points = [[0, 1, 0], [0, 2, 0]]\n"), "");
}

// A key the scene does not use is said, not taken silently: mu outside Coulomb mode, slope
// keys with the slope off, floor keys with floor and slope off (a probe's static mode with
// mu = 0 ran as Coulomb with mu = 1000 with no word).
TEST(Scene, KeysTheSceneDoesNotUseAreNamed) {
  auto warnings_of = [](const std::vector<std::string>& set) {
    testing::internal::CaptureStderr();
    parse_scene("", "w.toml", set);
    return testing::internal::GetCapturedStderr();
  };
  EXPECT_NE(warnings_of({"contact.mode=\"sliding\"", "contact.mu=0.9"}).find("contact.mu is not used"), std::string::npos);
  EXPECT_NE(warnings_of({"contact.mode=\"static\"", "contact.mu=0"}).find("contact.mu is not used"), std::string::npos);
  EXPECT_EQ(warnings_of({"contact.mode=\"coulomb\"", "contact.mu=0.9"}), "");
  EXPECT_NE(warnings_of({"slope.angle_deg=-1"}).find("slope.angle_deg is not used: slope.enabled is false"),
            std::string::npos);
  EXPECT_EQ(warnings_of({"slope.enabled=true", "slope.angle_deg=20"}), "");
  EXPECT_NE(warnings_of({"floor.enabled=false", "floor.normal=[0, 1, 0]"}).find("floor.normal is not used"),
            std::string::npos);
  EXPECT_EQ(warnings_of({"floor.enabled=false", "slope.enabled=true", "floor.normal=[0, 1, 0]"}), "");
}
