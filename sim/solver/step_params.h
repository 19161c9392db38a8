#pragma once
// Host side: the live parameters (solver.h) turned into what the step kernels read, the
// same for every backend.
#include <stdexcept>
#include <vector>

#include "sim/fem/central_difference.h"
#include "sim/fem/element_law.h"
#include "sim/fem/neo_hookean.h"
#include "sim/solver/solver.h"

namespace softtled {

template <class T>
inline StepParams<T> step_params_from(const PhysicsParams& p, double dt_mid = 0) {
  if (p.planes.size() > std::size_t(kMaxPlanes)) throw std::invalid_argument("too many planes");
  StepParams<T> s = make_step_params<T>(p.dt, p.alpha, p.g, p.beta, dt_mid);
  s.contact.nplanes = int(p.planes.size());
  for (std::size_t i = 0; i < p.planes.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      s.contact.planes[i].p[k] = T(p.planes[i].point[k]);
      s.contact.planes[i].n[k] = T(p.planes[i].normal[k]);
    }
  if (p.obstacles.size() > std::size_t(kMaxObstacles)) throw std::invalid_argument("too many obstacles");
  s.contact.nobstacles = int(p.obstacles.size());
  for (std::size_t i = 0; i < p.obstacles.size(); ++i) s.contact.obstacles[i] = obstacle_from<T>(p.obstacles[i], p.dt);
  s.contact.mode = p.contact_mode;
  s.contact.mu = T(p.mu);
  return s;
}

template <class T>
inline NeoHookean<T> material_from(const PhysicsParams& p) {
  return neo_hookean_from_E_nu<T>(p.E, p.nu, p.material_model);
}

// Each body's law: its own nu, model and element where it has them, else the scene's
// live ones (empty without per-body laws).
inline std::vector<BodyLaw> resolved_laws(const PhysicsParams& p) {
  std::vector<BodyLaw> v;
  for (const BodyLaw& o : p.body_laws)
    v.push_back({o.nu > -1 ? o.nu : p.nu, o.model >= 0 ? o.model : int(p.material_model),
                 o.element >= 0 ? o.element : int(p.element)});
  return v;
}

// What a backend's step reads from the live parameters: Solver::set_params of every
// backend is `config_ = step_config_from<T>(p)` (plus its own cache invalidation).
template <class T>
struct StepConfig {
  StepParams<T> step{};
  NeoHookean<T> mat = neo_hookean_from_E_nu<T>(3000, 0.49);
  // The stages the step runs: T4ANP where any body's element is T4ANP (a T4 body's
  // elements then keep their own volumetric response, element_law.h).
  int element = kT4;  // ElementType
  std::vector<ElementLaw<T>> laws;  // one per body (PhysicsParams::body_laws), or empty
};

template <class T>
inline StepConfig<T> step_config_from(const PhysicsParams& p) {
  StepConfig<T> c;
  c.step = step_params_from<T>(p);
  c.mat = material_from<T>(p);
  c.element = p.element;
  for (const BodyLaw& l : resolved_laws(p)) {
    if (l.element == kT4ANP && l.model != kTaylorNeoHookean)
      throw std::invalid_argument("T4ANP is implemented for the neo_hookean model only");
    c.laws.push_back({neo_hookean_from_E_nu<T>(p.E, l.nu, l.model), l.element});
  }
  if (!c.laws.empty()) {
    c.element = kT4;
    for (const ElementLaw<T>& l : c.laws)
      if (l.element == kT4ANP) c.element = kT4ANP;
  }
  return c;
}

}  // namespace softtled
