// The accuracy study in miniature (the full sweep is `softtled accuracy`): on the torus's
// first impact, refining the mesh lowers the error against a finer reference, and at
// nu = 0.49 the locking-free T4ANP lowers it at equal mesh (equal cost order).
#include <gtest/gtest.h>

#include "scene_helpers.h"
#include "analysis/accuracy_study.h"

using namespace softtled;
using namespace softtled::test;

TEST(AccuracyTrade, RefinementAndT4ANPReduceTheError) {
  const std::string scene = assets_dir() + "/scenes/torus_drop.toml";
  const double t_end = 0.04, t2 = 0.04;
  const AccuracyTimes times{t_end, 0.03, t2};  // through the first compression (contact at 0.02 s)
  const AccuracyRun ref = run_accuracy_variant(scene, "cpu", {"91x19", "double", "T4ANP", 0.5}, times);
  const FieldSampler sampler(*ref.mesh);
  auto err = [&](const std::string& level, const std::string& element) {
    const AccuracyRun r = run_accuracy_variant(scene, "cpu", {level, "double", element, 0.5}, times);
    const AccuracyErrors e = compare_runs(r, ref, sampler, t_end);
    std::printf("[accuracy] %-6s %-6s %5d tets: mean nodal error at %.2f s = %.4f mm, centroid RMS %.4f mm\n", level.c_str(),
                element.c_str(), r.ntet, t2, e.mean_err[1] * 1e3, e.centroid_rms * 1e3);
    return e;
  };
  const AccuracyErrors c24 = err("24x6", "T4ANP"), c45 = err("45x9", "T4ANP"), t45 = err("45x9", "T4");
  EXPECT_LT(c45.mean_err[1], c24.mean_err[1]) << "refinement must reduce the error";
  EXPECT_LT(c45.centroid_rms, c24.centroid_rms);
  EXPECT_LT(c45.mean_err[1], 0.5 * t45.mean_err[1]) << "T4ANP must at least halve the T4 error at nu = 0.49";
  // The study's own sanity: the reference compared with itself has no error.
  EXPECT_LT(compare_runs(ref, ref, sampler, t_end).max_err[1], 1e-12);
}
