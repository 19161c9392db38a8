#pragma once
// Mesh obstacles' distance grids (obstacle_sdf.h) as a backend holds them: one copy of each
// grid's values in the backend's memory and precision (Buffer: a host vector, a device
// buffer), made when a grid first appears in the parameters and dropped when no obstacle
// uses it any more (not per set_params: a moving obstacle sets the parameters every step),
// and the step parameters pointed at those copies.
#include <algorithm>
#include <memory>
#include <utility>
#include <vector>

#include "sim/fem/central_difference.h"
#include "sim/solver/solver.h"

namespace softtled {

template <class T, class Buffer>
class ObstacleGrids {
 public:
  // make(const SdfGrid&) -> Buffer: the values in T where the backend reads them.
  template <class Make>
  void hold(const PhysicsParams& p, Make&& make) {
    std::vector<std::pair<std::shared_ptr<const SdfGrid>, Buffer>> kept;
    for (const ObstacleSpec& o : p.obstacles) {
      if (o.shape != kObstacleMesh || !o.sdf) continue;
      if (std::any_of(kept.begin(), kept.end(), [&](const auto& k) { return k.first == o.sdf; })) continue;
      auto it = std::find_if(grids_.begin(), grids_.end(), [&](const auto& g) { return g.first == o.sdf; });
      if (it != grids_.end()) kept.push_back(std::move(*it));
      else kept.emplace_back(o.sdf, make(*o.sdf));
    }
    grids_ = std::move(kept);
  }
  // s (from p): each mesh obstacle's view reads the held values; data(const Buffer&) -> const T*.
  template <class Data>
  void point(const PhysicsParams& p, StepParams<T>& s, Data&& data) const {
    for (std::size_t i = 0; i < p.obstacles.size(); ++i) {
      const ObstacleSpec& o = p.obstacles[i];
      if (o.shape != kObstacleMesh || !o.sdf) continue;
      for (const auto& g : grids_)
        if (g.first == o.sdf) s.contact.obstacles[i].sdf.value = data(g.second);
    }
  }

 private:
  std::vector<std::pair<std::shared_ptr<const SdfGrid>, Buffer>> grids_;
};

}  // namespace softtled
