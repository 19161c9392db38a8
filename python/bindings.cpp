// The pybind11 glue of `import softtled` (the compiled part, softtled._softtled): the
// exceptions, the Simulation class over PySimulation (py_simulation.h), NumPy arrays of
// the state and rest mesh, and two helpers of `softtled run`'s output. The Python side
// (softtled/__init__.py) adds scenes given as dicts.
//
// Arrays: what is a view and what is a copy (README, "Python").
//  * displacements(), contact_state(): read-only views of the Simulation's host copy of
//    the live state (Simulation::state(): the solver's u, in float or double, copied to
//    double once per step count; the watchdog and diagnostics read the same copy). No
//    further copy. The view follows that copy: the module refreshes it after every call,
//    so a view shows the state after the latest advance()/step() (take .copy() to keep one).
//  * rest_positions(), tets(), surface_triangles(), lumped_mass(): read-only views of the
//    rest mesh (never changes).
//  * positions() (X + u) and velocities() (du / dt) are computed: new arrays.
//  * device_displacements(), device_increments() (GPU backend): the solver's live
//    buffers in GPU memory through __cuda_array_interface__ (DeviceArray below), no copy.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>

#include "app/cli_support.h"
#include "python/py_render.h"
#include "python/py_simulation.h"
#include "sim/core/input_error.h"
#include "sim/io/output_file.h"
#include "sim/io/vtu_writer.h"

namespace py = pybind11;
using namespace softtled;

namespace softtled_py {

// After a failed conversion of v to a number: raises the error v's own __float__,
// __index__ or __int__ raised (a RuntimeError of the caller's), which pybind11's casters
// clear and report as a generic TypeError. A plain mismatch (TypeError) or an overflow
// returns, for the caller's TypeError. Only objects of the number protocol are asked:
// float("0.5") would parse a str.
inline void raise_own_number_error(py::handle v, bool integral) {
  PyObject* o = v.ptr();
  if (!PyNumber_Check(o)) return;
  PyObject* r = nullptr;
  if (!integral) r = PyNumber_Float(o);
  else if (PyIndex_Check(o)) r = PyNumber_Index(o);
  else if (!PyFloat_Check(o) && !Py_TYPE(o)->tp_as_number->nb_float) r = PyNumber_Long(o);  // as pybind11's int caster
  else return;
  if (r) {
    Py_DECREF(r);
    return;
  }
  if (PyErr_ExceptionMatches(PyExc_TypeError) || PyErr_ExceptionMatches(PyExc_OverflowError)) {
    PyErr_Clear();
    return;
  }
  throw py::error_already_set();
}

// A number argument converted as T's caster converts it, but raising the object's own
// error (raise_own_number_error) where that fails.
template <class T>
struct Num {
  T v;
  operator T() const { return v; }
};

}  // namespace softtled_py

namespace pybind11::detail {
template <class T>
struct type_caster<softtled_py::Num<T>> {
  PYBIND11_TYPE_CASTER(softtled_py::Num<T>, make_caster<T>::name);
  bool load(handle src, bool convert) {
    make_caster<T> c;
    if (c.load(src, convert)) {
      value.v = cast_op<T>(c);
      return true;
    }
    if (convert) softtled_py::raise_own_number_error(src, std::is_integral_v<T>);
    return false;
  }
  static handle cast(const softtled_py::Num<T>& n, return_value_policy policy, handle parent) {
    return make_caster<T>::cast(n.v, policy, parent);
  }
};
}  // namespace pybind11::detail

using softtled_py::Num;

namespace {

// A read-only NumPy view of n rows x cols values at p (row stride row_bytes, column stride
// col_bytes) that keeps `owner` (the Python Simulation) alive.
template <class T>
py::array view(const T* p, py::ssize_t n, py::ssize_t cols, py::ssize_t row_bytes, py::ssize_t col_bytes,
               const py::object& owner) {
  std::vector<py::ssize_t> shape{n}, strides{row_bytes};
  if (cols > 0) {
    shape.push_back(cols);
    strides.push_back(col_bytes);
  }
  py::array a(py::dtype::of<T>(), shape, strides, p, owner);
  a.attr("setflags")(py::arg("write") = false);
  return a;
}

// n x 3 array of an SoA field (3 x n, component-major) f(k, i).
template <class F>
py::array_t<double> rows_of(int n, F f) {
  py::array_t<double> a({py::ssize_t(n), py::ssize_t(3)});
  auto r = a.mutable_unchecked<2>();
  for (int i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k) r(i, k) = f(k, i);
  return a;
}

// Whether self is a Simulation whose C++ state exists. The type is checked first: the
// instance layout read below is a pybind11 instance's only for a Simulation (None or 3
// reinterpreted as one crashed).
bool is_initialised(py::handle self) {
  return py::isinstance<PySimulation>(self) &&
         reinterpret_cast<py::detail::instance*>(self.ptr())->get_value_and_holder().holder_constructed();
}

// The Simulation behind self, refused with a TypeError where there is none: an instance
// made by __new__ alone (its methods reached through the class, past __getattribute__'s
// guard, had read uninitialised memory: a crash) or an object of another type. Every
// method takes self as py::handle and goes through here: one bound to PySimulation&
// directly skips the check.
PySimulation& self_of(py::handle self) {
  if (!py::isinstance<PySimulation>(self))
    throw py::type_error("Simulation method called on a " + std::string(py::str(self.get_type())));
  if (!is_initialised(self))
    throw py::type_error("this Simulation was never initialised (create it with softtled.Simulation(scene), not __new__ alone)");
  return self.cast<PySimulation&>();
}

// A path argument as the constructor takes it: a str or an os.PathLike (pathlib.Path).
std::string path_of(py::handle v, const char* what) {
  if (py::isinstance<py::str>(v)) return v.cast<std::string>();
  if (py::isinstance<py::bytes>(v)) return std::string(py::bytes(py::reinterpret_borrow<py::object>(v)));  // as before
  if (py::hasattr(v, "__fspath__")) {
    const py::object p = py::module_::import("os").attr("fspath")(v);
    if (py::isinstance<py::bytes>(p)) return std::string(py::bytes(p));
    return p.cast<std::string>();
  }
  throw py::type_error(std::string(what) + ": path must be a str, bytes or os.PathLike, not " +
                       std::string(py::str(v.get_type().attr("__name__"))));
}

// One live state array in GPU memory for CuPy, PyTorch or Numba: __cuda_array_interface__
// version 3 (https://numba.readthedocs.io/en/stable/cuda/cuda_array_interface.html),
// nnode x 3 in the solver's precision over its struct-of-arrays layout (strides: one value
// to the next row, nnode values to the next component), rows in the solver's node order
// (`rows`: the mesh node of each row). The interface points at the solver's own buffer:
// no copy, it shows each new step, and `stream` is the stream the steps run on, which a
// consumer orders itself after.
struct DeviceArray {
  py::object owner;  // the Simulation: keeps the buffer and `rows` alive
  const void* data = nullptr;
  int nnode = 0, value_bytes = 0;
  void* stream = nullptr;
  py::array rows;
};

DeviceArray device_array(const py::object& self, bool increments, const char* name) {
  const DeviceStateView v = self_of(self).sim().device_state();
  if (!v.u)
    throw py::value_error(std::string(name) + "(): backend '" + self_of(self).sim().backend() +
                          "' keeps its state in host memory; use displacements() (a NumPy view)");
  DeviceArray a;
  a.owner = self;
  a.data = increments ? v.du : v.u;
  a.nnode = v.nnode;
  a.value_bytes = v.value_bytes;
  a.stream = v.stream;
  a.rows = view(v.rows->data(), py::ssize_t(v.rows->size()), 0, sizeof(int), 0, self);
  return a;
}

// The DeviceArray behind self, refused as self_of refuses: DeviceArray.__new__ alone has
// no C++ object, and a property bound to DeviceArray& read garbage (a crash).
const DeviceArray& device_of(py::handle self) {
  if (!py::isinstance<DeviceArray>(self) ||
      !reinterpret_cast<py::detail::instance*>(self.ptr())->get_value_and_holder().holder_constructed())
    throw py::type_error("DeviceArray: not one made by Simulation.device_displacements() or device_increments()");
  return self.cast<const DeviceArray&>();
}

py::dict cuda_array_interface(py::handle self) {
  const DeviceArray& a = device_of(self);
  py::dict d;
  d["shape"] = py::make_tuple(a.nnode, 3);
  d["typestr"] = a.value_bytes == 4 ? "<f4" : "<f8";
  // Not flagged read-only: PyTorch refuses such an interface ("the read only flag is not
  // supported", torch 2.11 on the H100). Writing through it changes the live state behind
  // the watchdog's back: the README says not to.
  d["data"] = py::make_tuple(reinterpret_cast<std::uintptr_t>(a.data), false);
  d["strides"] = py::make_tuple(a.value_bytes, py::ssize_t(a.nnode) * a.value_bytes);
  d["version"] = 3;
  d["stream"] = reinterpret_cast<std::uintptr_t>(a.stream);
  return d;
}

// go(interrupted) steps, polling Python's Ctrl-C through interrupted and returning true
// when it stopped for it (KeyboardInterrupt raised here); the host copy refreshed
// afterwards (also after a watchdog stop, which rolled the state back).
template <class Go>
void run_interruptible(PySimulation& s, Go go) {
  bool stopped = false;
  try {
    stopped = go([] { return PyErr_CheckSignals() != 0; });
  } catch (...) {
    s.refresh();
    throw;
  }
  s.refresh();
  if (stopped) throw py::error_already_set();
}

// n steps, Ctrl-C answered between chunks.
void run_steps(PySimulation& s, long n) {
  run_interruptible(s, [&](auto interrupted) { return s.step(n, interrupted); });
}

// The adaptive step to time t_end, Ctrl-C answered about every kStopCheckSteps steps.
void run_adaptive(PySimulation& s, double t_end, const std::string& what) {
  run_interruptible(s, [&](auto interrupted) { return s.advance_to_adaptive(t_end, what, interrupted); });
}

// A NumPy boolean (np.bool_, or a 0-d bool array) is a bool, not the number 0 or 1 its
// __float__ gives: floor=np.bool_(False) raised "takes a bool", mu=np.bool_(True) set mu = 1.
bool numpy_bool(const py::handle& v) {
  if (!py::hasattr(v, "dtype") || (py::hasattr(v, "ndim") && v.attr("ndim").cast<int>() != 0)) return false;
  return py::str(v.attr("dtype").attr("kind")).cast<std::string>() == "b";
}

// v as pybind11 converts a float argument, or the error v's own __float__ raised.
double to_double(const py::handle& v) {
  py::detail::make_caster<double> c;
  if (c.load(v, true)) return py::detail::cast_op<double>(c);
  softtled_py::raise_own_number_error(v, false);
  throw py::cast_error("not a number");
}

// Each item of a vector value a number, not itself a sequence (np.zeros((3, 1)) passed as
// three one-element arrays).
std::vector<double> flat_numbers(const std::string& key, const py::handle& v) {
  std::vector<double> out;
  for (const py::handle item : v) {
    if (py::isinstance<py::str>(item) || py::hasattr(item, "__len__") || py::isinstance<py::bool_>(item) || numpy_bool(item))
      throw py::type_error("set_params: " + key + ": expected a flat sequence of numbers, got an item " +
                           std::string(py::repr(item)));
    out.push_back(to_double(item));
  }
  return out;
}

ParamValue param_value_cast(const std::string& key, const py::handle& v) {
  ParamValue p;
  if (py::isinstance<py::bytes>(v) || py::isinstance<py::bytearray>(v))
    throw py::type_error("set_params: " + key + ": got bytes; give a str (e.g. 'static'), a number or a sequence of numbers");
  if (py::isinstance<py::bool_>(v) || numpy_bool(v)) {
    p.kind = ParamValue::kBool;
    p.flag = PyObject_IsTrue(v.ptr()) == 1;
  } else if (py::isinstance<py::str>(v)) {
    p.kind = ParamValue::kString;
    p.text = v.cast<std::string>();
  } else if (py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v) || py::hasattr(v, "__float__")) {
    if (py::hasattr(v, "__len__") && !(py::hasattr(v, "ndim") && v.attr("ndim").cast<int>() == 0)) {  // a NumPy array of one value passes __float__ too
      p.kind = ParamValue::kVector;
      p.vec = flat_numbers(key, v);
    } else {
      p.kind = ParamValue::kNumber;
      p.number = to_double(v);
    }
  } else if (py::isinstance<py::sequence>(v) || py::hasattr(v, "__array__")) {  // ordered: not a set or generator
    p.kind = ParamValue::kVector;
    p.vec = flat_numbers(key, v);
  } else {
    throw py::type_error("set_params: " + key + ": unsupported value type " + std::string(py::str(v.get_type())));
  }
  return p;
}

ParamValue param_value(const std::string& key, const py::handle& v) {
  try {
    return param_value_cast(key, v);
  } catch (const py::cast_error&) {  // '0' in a vector, an int beyond double: a type error, as documented
    std::string got = py::repr(v);
    if (got.size() > 60) got = got.substr(0, 57) + "...";
    throw py::type_error("set_params: " + key + ": expected a number (within a double's range) or a sequence of numbers, "
                         "got " + got);
  }
}

py::dict diagnostics_dict(Simulation& sim) {
  const Diagnostics d = sim.diagnostics();
  py::dict r;
  r["t"] = d.t;
  r["centroid"] = py::make_tuple(d.centroid[0], d.centroid[1], d.centroid[2]);
  r["min_gap"] = d.min_gap;
  r["ke"] = d.ke;
  r["se"] = d.se;
  r["pe"] = d.pe;
  r["n_contact"] = d.n_contact;
  r["n_stick"] = d.n_stick;
  r["max_u"] = d.max_u;
  r["tracked"] = d.tracked;              // 3 per tracked node: displacement [m]
  r["body_centroid"] = d.body_centroid;  // 3 per body with >= 2 bodies, else empty
  py::dict w;
  w["trips"] = sim.watchdog_trips();  // adaptive step: trips survived so far
  w["dt_over_dt_cr"] = sim.params().dt / sim.time_step().dt_cr;
  r["watchdog"] = w;
  return r;
}

py::dict params_dict(py::handle self) {
  PySimulation& s = self_of(self);
  const PhysicsParams& p = s.sim().params();
  py::dict r;
  r["E"] = p.E;
  r["nu"] = p.nu;
  r["alpha"] = p.alpha;
  r["beta"] = p.beta;
  r["mu"] = p.mu;
  r["contact_mode"] = contact_mode_name(p.contact_mode);
  r["body_contact"] = p.body_contact;
  r["self_contact"] = p.self_contact;
  r["dt"] = p.dt;
  r["dt_auto"] = p.dt_auto;
  r["dt_adaptive"] = p.dt_adaptive;
  r["lambda"] = p.lambda;
  r["dt_max"] = p.dt_max;
  r["g"] = py::make_tuple(p.g[0], p.g[1], p.g[2]);
  r["floor"] = s.floor_on();
  r["slope"] = s.slope_on();
  r["slope_angle_deg"] = s.slope_deg();  // asked for; slope_now(): where it is
  r["slope_now_deg"] = s.slope_now();
  r["slope_turning"] = s.slope_turning();
  py::list planes;  // [m]: the floor first when on, then the slope (scene_planes)
  for (const PlaneSpec& pl : p.planes) {
    py::dict d;
    d["point"] = py::make_tuple(pl.point[0], pl.point[1], pl.point[2]);
    d["normal"] = py::make_tuple(pl.normal[0], pl.normal[1], pl.normal[2]);
    planes.append(d);
  }
  r["planes"] = planes;
  return r;
}

py::dict time_step_dict(Simulation& sim) {
  const TimeStepInfo& t = sim.time_step();
  py::dict r;
  r["c"] = t.c;
  r["min_Le"] = t.min_Le;
  r["dt_le"] = t.dt_le;
  r["dt_eigen"] = t.dt_eigen;
  r["dt_cr"] = t.dt_cr;
  r["dt"] = t.dt;
  r["dt_live"] = t.dt_live;
  return r;
}

}  // namespace

PYBIND11_MODULE(_softtled, m) {
  m.doc() = "SoftTLED soft-body simulation (TLED FEM): the compiled part of `import softtled`";

  // The CLI's exit-2 errors: the message is the text after "softtled: error: ".
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
  // The CLI's exit-5 errors (no EGL, disk full, write errors).
  py::register_exception<ResourceError>(m, "ResourceError", PyExc_RuntimeError);
  // The CLI's exit 4: the watchdog stopped a diverging run (the state is rolled back).
  static py::exception<SimulationDiverged> diverged(m, "SimulationDiverged", PyExc_RuntimeError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const SimulationDiverged& e) {
      py::object err = py::reinterpret_borrow<py::object>(diverged)(e.what());
      err.attr("element") = e.element;
      PyErr_SetObject(diverged.ptr(), err.ptr());
    }
  });

  py::class_<DeviceArray>(m, "DeviceArray", "A live state array in GPU memory (Simulation.device_displacements).")
      .def_property_readonly("__cuda_array_interface__", &cuda_array_interface)
      .def_property_readonly("rows", [](py::handle self) { return device_of(self).rows; }, "mesh node of each row")
      .def_property_readonly("shape", [](py::handle self) { return py::make_tuple(device_of(self).nnode, 3); });
  m.def(
      "time_decimals",
      [](Num<double> dt) {
        if (!(dt > 0) || !std::isfinite(dt)) throw InputError("time_decimals: dt = " + number_text(dt) + ": must be finite and > 0");
        return time_decimals(dt);
      },
      py::arg("dt"),
        "Decimals of `softtled run`'s CSV column t: 3 significant digits of dt, at least 6.");
  m.def(
      "step_count", [](Num<double> duration, Num<double> dt) { return checked_step_count(duration, dt, "step_count"); },
      py::arg("duration"), py::arg("dt"), "Steps to cover duration at dt, rounded, as `softtled run` counts them.");
  m.attr("CHUNK_STEPS") = PySimulation::kChunkSteps;
  m.attr("HAVE_RENDER") = png_render_available();
  m.attr("LIVE_PARAMETERS") = PySimulation::param_names();

  py::class_<PySimulation>(m, "Simulation")
      .def(py::init<const std::string&, const std::string&, const std::string&, const std::string&,
                    const std::vector<std::string>&>(),
           py::arg("path"), py::arg("text"), py::arg("source"), py::arg("backend"), py::arg("overrides"),
           "Low level: a scene file (path) or TOML text (text, named source); use softtled.Simulation.")
      // An instance made by __new__ alone has no PySimulation: pybind11 would hand its
      // methods uninitialised memory (a crash). Every attribute but the dunders (__init__
      // among them) is refused until __init__ has run.
      .def_static("_is_initialised", [](py::handle self) { return is_initialised(self); })
      .def("__getattribute__",
           [](py::handle self, const py::str& name) {
             const std::string n = name;
             if (!py::isinstance<PySimulation>(self))  // reached through the class with another object
               throw py::type_error("Simulation.__getattribute__ called on a " + std::string(py::str(self.get_type())));
             if (n.rfind("__", 0) != 0 && n != "_is_initialised" && !is_initialised(self))
               throw py::type_error("Simulation." + n + ": this Simulation was never initialised (create it with "
                                    "softtled.Simulation(scene), not __new__ alone)");
             PyObject* r = PyObject_GenericGetAttr(self.ptr(), name.ptr());
             if (!r) throw py::error_already_set();
             return py::reinterpret_steal<py::object>(r);
           })
      // ---- stepping ----
      .def(
          "step", [](py::handle self_, Num<long> n) {
            PySimulation& s = self_of(self_);
            if (n < 0) throw py::value_error("step: n must be >= 0");
            if (double(n) > kMaxRunSteps)  // as advance and softtled run: the step count past it overflows
              throw py::value_error("step: n = " + std::to_string(n) + " is above the limit of 1e11 steps");
            run_steps(s, n);
          },
          py::arg("n") = 1,
          "n steps, as `softtled run` takes them: chunks of at most CHUNK_STEPS, the watchdog checking after each "
          "(SimulationDiverged: the state is rolled back to the last healthy check); Ctrl-C between chunks.")
      .def(
          "advance", [](py::handle self_, Num<double> seconds) {
            PySimulation& s = self_of(self_);
            if (!(seconds >= 0) || !std::isfinite(seconds)) throw InputError("advance: seconds must be finite and >= 0");
            const std::string what = "advance(" + number_text(seconds) + ")";
            if (s.sim().params().dt_adaptive) {
              // As a fixed step: a span shorter than half the step in use takes no step and is
              // refused, not ignored (`while sim.time < T: sim.advance(h)` never ended).
              (void)s.steps_for(seconds, what);
              run_adaptive(s, s.sim().time() + seconds, what);
            } else {
              run_steps(s, s.steps_for(seconds, what));
            }
          },
          py::arg("seconds"),
          "Simulated seconds: round(seconds / dt) steps as step(); with time.dt = \"adaptive\" to time + seconds.")
      .def(
          "advance_to", [](py::handle self_, Num<double> t) {
            PySimulation& s = self_of(self_);
            if (!std::isfinite(t)) throw InputError("advance_to: t must be finite");
            const std::string what = "advance_to(" + number_text(t) + ")";
            // The facade steps to t within half a step (Simulation::step_to): a t further
            // back cannot be reached, and doing nothing would hide that.
            const double now = s.sim().time();
            if (t < now - 0.5 * s.sim().params().dt)
              throw InputError(what + ": t = " + number_text(t) + " s is earlier than the current time " + number_text(now) +
                               " s; the simulation only goes forward (reset() starts again from t = 0)");
            // A t within half a step ahead is reached already, as one within half a step
            // behind (a sampling loop finer than dt raised "shorter than half the time step").
            if (s.sim().params().dt_adaptive)
              run_adaptive(s, t, what);
            else if (std::nearbyint((t - now) / s.sim().params().dt) >= 1)
              run_steps(s, s.steps_for(t - now, what));
          },
          py::arg("t"),
          "To simulated time t (as `softtled run` reaches its output times): the step nearest t; a t within half a "
          "step of the current time takes none, and one more than half a step before it raises InputError (the "
          "simulation only goes forward).")
      .def(
          "reset", [](py::handle self_) {
            PySimulation& s = self_of(self_);
            s.sim().reset();
            s.refresh();
          },
          "Back to the initial state (the viewer's drop again); parameters stay as set.")
      .def_property_readonly("time", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().time(); }, "simulated time [s]")
      .def_property_readonly("dt", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().params().dt; }, "time step in use [s]")
      .def_property_readonly("dt_cr", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().time_step().dt_cr; },
                             "stable step bound [s] (min of Le/c and 2/omega_max)")
      .def_property_readonly("steps", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().total_steps(); }, "steps taken")
      .def("time_step", [](py::handle self_) { PySimulation& s = self_of(self_); return time_step_dict(s.sim()); }, "Stable-step details [m/s, m, s].")
      // ---- the scene ----
      .def_property_readonly("backend", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().backend(); })
      .def_property_readonly("precision", [](py::handle self_) { PySimulation& s = self_of(self_); return std::string(precision_name(s.scene().precision)); })
      .def_property_readonly("source", [](py::handle self_) { PySimulation& s = self_of(self_); return s.scene().source; })
      .def_property_readonly("duration", [](py::handle self_) { PySimulation& s = self_of(self_); return s.scene().duration; }, "the scene's time.duration [s]")
      .def_property_readonly("output_every", [](py::handle self_) { PySimulation& s = self_of(self_); return s.scene().output_every; },
                             "the scene's time.output_every [s]")
      .def_property_readonly("adaptive", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().params().dt_adaptive; },
                             "time.dt = \"adaptive\"")
      .def_property_readonly("nnode", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().mesh().nnode(); })
      .def_property_readonly("ntet", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().mesh().ntet(); })
      .def_property_readonly("nbody", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().mesh().nbody(); })
      .def_property_readonly("tracked_nodes", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().tracked_nodes(); },
                             "node of each output.track_points entry")
      .def_property_readonly("fixed_node_count", [](py::handle self_) { PySimulation& s = self_of(self_); return s.sim().fixed_node_count(); })
      // ---- arrays ----
      .def(
          "displacements", [](py::object self) {
            PySimulation& s = self_of(self);
            const std::vector<double>& u = s.sim().state().u;
            const py::ssize_t n = s.sim().mesh().nnode();
            return view(u.data(), n, 3, sizeof(double), n * py::ssize_t(sizeof(double)), self);
          },
          "u [m], nnode x 3: a read-only view (no copy) of the host copy of the state, which the module refreshes "
          "after every step; .copy() keeps a snapshot.")
      .def(
          "contact_state", [](py::object self) {
            PySimulation& s = self_of(self);
            const std::vector<std::uint8_t>& c = s.sim().state().contact;
            return view(c.data(), py::ssize_t(c.size()), 0, 1, 0, self);
          },
          "ContactState per node (0 free, 1 sticking, 2 sliding): a read-only view like displacements().")
      .def(
          "positions", [](py::handle self_) {
            PySimulation& s = self_of(self_);
            const HostState& st = s.sim().state();
            const std::vector<double>& X = s.sim().mesh().X;
            const int n = s.sim().mesh().nnode();
            return rows_of(n, [&](int k, int i) { return X[3 * i + k] + st.u[std::size_t(k) * n + i]; });
          },
          "x = X + u [m], nnode x 3 (a new array).")
      .def(
          "velocities", [](py::handle self_) {
            PySimulation& s = self_of(self_);
            const HostState& st = s.sim().state();
            const double dt = s.sim().params().dt;
            const int n = s.sim().mesh().nnode();
            return rows_of(n, [&](int k, int i) { return st.du[std::size_t(k) * n + i] / dt; });
          },
          "du / dt [m/s], nnode x 3 (a new array): the integrator's half-step velocity over (t - dt, t), "
          "the one the CSV's ke uses.")
      .def(
          "device_displacements", [](py::object self) { return device_array(self, false, "device_displacements"); },
          "u [m] in GPU memory (CUDA backend): an object with __cuda_array_interface__ (cupy.asarray, "
          "torch.as_tensor) over the solver's live buffer, no copy; nnode x 3 in the solver's precision, row r "
          "is mesh node .rows[r]. ValueError on a CPU backend.")
      .def(
          "device_increments", [](py::object self) { return device_array(self, true, "device_increments"); },
          "du = u(t) - u(t - dt) [m] in GPU memory, as device_displacements() (du / dt is velocities()).")
      .def(
          "rest_positions", [](py::object self) {
            const TetMesh& m = self_of(self).sim().mesh();
            return view(m.X.data(), m.nnode(), 3, 3 * sizeof(double), sizeof(double), self);
          },
          "X [m], nnode x 3: read-only view of the rest mesh.")
      .def(
          "tets", [](py::object self) {
            const TetMesh& m = self_of(self).sim().mesh();
            return view(m.tet.data(), m.ntet(), 4, 4 * sizeof(int), sizeof(int), self);
          },
          "ntet x 4 node indices: read-only view.")
      .def(
          "surface_triangles", [](py::object self) {
            const TetMesh& m = self_of(self).sim().mesh();
            return view(m.boundary_tri.data(), m.nbtri(), 3, 3 * sizeof(int), sizeof(int), self);
          },
          "nbtri x 3 boundary triangles (outward): read-only view.")
      .def(
          "lumped_mass", [](py::object self) {
            const std::vector<double>& mass = self_of(self).sim().lumped_mass();
            return view(mass.data(), py::ssize_t(mass.size()), 0, sizeof(double), 0, self);
          },
          "lumped mass per node [kg]: read-only view.")
      // ---- parameters and measures ----
      .def(
          "set_params", [](py::handle self_, py::kwargs kw) {
            PySimulation& s = self_of(self_);
            std::map<std::string, ParamValue> changes;
            const auto& names = PySimulation::param_names();
            for (const auto& [k, v] : kw) {
              const std::string key = k.cast<std::string>();
              if (std::find(names.begin(), names.end(), key) == names.end()) {
                std::string known;
                for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
                throw py::type_error("set_params() got an unexpected keyword argument '" + key +
                                     "' (live parameters: " + known + ")");
              }
              changes[key] = param_value(key, v);
            }
            try {
              return s.set_params(changes);
            } catch (const std::invalid_argument& e) {  // a value of the wrong kind
              throw py::type_error(e.what());
            }
          },
          "Live changes as the viewer's panel makes them (LIVE_PARAMETERS); returns a warning (a fixed dt "
          "above dt_cr is clamped) or ''.")
      .def("params", &params_dict, "The live parameters now.")
      .def("diagnostics", [](py::handle self_) { PySimulation& s = self_of(self_); return diagnostics_dict(s.sim()); },
           "The CSV's measures of the state now (energies [J], centroid [m], min_gap [m], contacts, watchdog).")
      // ---- output ----
      .def(
          "write_vtu", [](py::handle self_, py::handle path_) {
            PySimulation& s = self_of(self_);
            const std::string path = path_of(path_, "write_vtu");
            check_output_file(path, "write_vtu");
            check_not_scene_input(s.scene(), "the scene", {path, "write_vtu", true});
            Simulation& sim = s.sim();
            write_vtu(path, sim.mesh(), &sim.state(), sim.time_step().dt, sim.materials());
          },
          py::arg("path"), "One ParaView .vtu of the state now (the point and cell data of `run --vtu`).")
      .def(
          "render_png", [](py::handle self_, py::handle path, Num<int> width, Num<int> height, const std::string& color,
                           Num<int> samples, Num<float> azimuth, Num<float> elevation, Num<float> zoom) {
            PySimulation& s = self_of(self_);
            const std::string file = path_of(path, "render_png");
            PngOptions o;
            o.width = width;
            o.height = height;
            o.color = color;
            o.samples = samples;
            o.azimuth_deg = azimuth;
            o.elevation_deg = elevation;
            o.zoom = zoom;
            return render_png(s.sim(), file, o);
          },
          py::arg("path"), py::arg("width") = 960, py::arg("height") = 720, py::arg("color") = "shaded",
          py::arg("samples") = 4, py::arg("azimuth") = 30.0f, py::arg("elevation") = 18.0f, py::arg("zoom") = 1.0f,
          "One PNG of the state now through `softtled render`'s EGL path (color: shaded, displacement, contact or "
          "von_mises, as render --color); returns the GL renderer's name. "
          "ResourceError (a RuntimeError) when no EGL context can be made.");
}
