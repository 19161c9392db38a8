// Scene files: defaults equal the paper's scene, overrides by dotted key, and every kind
// of bad input names the offending key.
#include <gtest/gtest.h>

#include "scene_helpers.h"
#include "sim/scene/scene.h"
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
  EXPECT_NE(error_of("", {"material.E=nan"}).find("material.E: must be finite"), std::string::npos);
  EXPECT_NE(error_of("[material]\nE = -5.0\n").find("material.E: value -5 out of range"), std::string::npos);
  EXPECT_NE(error_of("[material]\nnu = 0.5\n").find("material.nu"), std::string::npos);
  EXPECT_NE(error_of("[material]\nrho = 0\n").find("material.rho"), std::string::npos);
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
    EXPECT_NE(std::string(e.what()).find("cannot open scene file"), std::string::npos);
  }
}
