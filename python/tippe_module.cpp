// The Python module `tippe`: run_scene_file, run_scene (a dict with a scene file's keys), the summary's fields as attributes.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <set>
#include <sstream>
#include <string>

#include <tippe/tippe.h>
#include <toml++/toml.h>

namespace py = pybind11;

namespace {

// A scene dict becomes the TOML document a scene file would be, so that it goes through the same
// reader with the same checks and messages (the label "dict" stands for the file).
toml::array to_toml_array(const py::handle& list, const std::string& key);

// The deepest dict a scene may be: a scene file's keys nest 3 deep, and the reader refuses keys of
// more than 64 parts (kMaxTomlKeyParts); deeper would recurse here without bound.
constexpr int kMaxDictDepth = 64;

// The dicts on the way from the root to the one being converted (by identity): a dict that
// contains itself is refused instead of recursing until the interpreter crashes.
using DictPath = std::set<const PyObject*>;

void insert_value(toml::table& t, const std::string& key, const py::handle& v, const std::string& where,
                  DictPath& open, int depth) {
  const std::string path = where.empty() ? key : where + "." + key;
  if (py::isinstance<py::bool_>(v)) {
    t.insert_or_assign(key, v.cast<bool>());
  } else if (py::isinstance<py::int_>(v)) {
    t.insert_or_assign(key, v.cast<long long>());
  } else if (py::isinstance<py::float_>(v)) {
    t.insert_or_assign(key, v.cast<double>());
  } else if (py::isinstance<py::str>(v)) {
    t.insert_or_assign(key, v.cast<std::string>());
  } else if (py::isinstance<py::dict>(v)) {
    if (open.count(v.ptr())) throw py::value_error(path + ": the dict contains itself (a cycle)");
    if (depth >= kMaxDictDepth)
      throw py::value_error(path.substr(0, 80) + "...: dicts nested deeper than " + std::to_string(kMaxDictDepth));
    open.insert(v.ptr());
    toml::table sub;
    for (const auto& kv : v.cast<py::dict>()) {
      if (!py::isinstance<py::str>(kv.first)) throw py::type_error(path + ": keys must be strings");
      insert_value(sub, kv.first.cast<std::string>(), kv.second, path, open, depth + 1);
    }
    open.erase(v.ptr());
    t.insert_or_assign(key, std::move(sub));
  } else if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    t.insert_or_assign(key, to_toml_array(v, path));
  } else {
    throw py::type_error(path + ": unsupported value of type " + std::string(py::str(v.get_type().attr("__name__"))));
  }
}

toml::array to_toml_array(const py::handle& list, const std::string& key) {
  toml::array a;
  for (const auto& item : list) {
    if (py::isinstance<py::bool_>(item)) a.push_back(item.cast<bool>());
    else if (py::isinstance<py::int_>(item)) a.push_back(item.cast<long long>());
    else if (py::isinstance<py::float_>(item)) a.push_back(item.cast<double>());
    else if (py::isinstance<py::str>(item)) a.push_back(item.cast<std::string>());
    else throw py::type_error(key + ": arrays hold numbers, booleans or strings");
  }
  return a;
}

std::string scene_dict_to_toml(const py::dict& d) {
  toml::table root;
  DictPath open = {d.ptr()};
  for (const auto& kv : d) {
    if (!py::isinstance<py::str>(kv.first)) throw py::type_error("scene keys must be strings");
    insert_value(root, kv.first.cast<std::string>(), kv.second, "", open, 1);
  }
  std::ostringstream os;
  os << root;
  return os.str();
}

// Columns as numpy arrays when numpy can be imported, lists otherwise.
py::dict trajectory_to_python(const tippe::TrajectoryColumns& t) {
  py::object np;
  try {
    np = py::module_::import("numpy");
  } catch (const py::error_already_set&) {
    np = py::none();
  }
  py::dict out;
  for (const std::string& c : t.columns) {
    py::object column = c == "surface" ? py::cast(t.surface) : py::cast(t.values.at(c));
    out[py::str(c)] = np.is_none() ? column : np.attr("asarray")(column);
  }
  return out;
}

py::object run(const tippe::RunSummary& s, const tippe::TrajectoryColumns& t) {
  py::object obj = py::cast(s);
  obj.attr("trajectory") = trajectory_to_python(t);
  return obj;
}

}  // namespace

PYBIND11_MODULE(tippe, m) {
  m.doc() = "Tippe-top bench: run the analytic reference on a scene and read its summary (the fields of summary.json).";
  m.attr("__version__") = tippe::version();
  py::register_exception<tippe::InputError>(m, "InputError", PyExc_ValueError);

  py::class_<tippe::SummaryEvent>(m, "Event")
      .def_readonly("name", &tippe::SummaryEvent::name)
      .def_readonly("time", &tippe::SummaryEvent::time)
      .def_readonly("detail", &tippe::SummaryEvent::detail)
      .def_readonly("value", &tippe::SummaryEvent::value)
      .def("__repr__", [](const tippe::SummaryEvent& e) { return "<Event " + e.name + " t=" + py::str(py::float_(e.time)).cast<std::string>() + ">"; });
  py::class_<tippe::SummaryMass>(m, "MassProperties")
      .def_readonly("mass", &tippe::SummaryMass::mass)
      .def_readonly("com_offset", &tippe::SummaryMass::com_offset)
      .def_readonly("inertia_transverse", &tippe::SummaryMass::inertia_transverse)
      .def_readonly("inertia_axial", &tippe::SummaryMass::inertia_axial);
  py::class_<tippe::SummaryWork>(m, "Work")
      .def_readonly("steps", &tippe::SummaryWork::steps)
      .def_readonly("rhs_evaluations", &tippe::SummaryWork::rhs_evaluations)
      .def_readonly("solver_iterations", &tippe::SummaryWork::solver_iterations)
      .def_readonly("wall_seconds", &tippe::SummaryWork::wall_seconds)
      .def_readonly("cpu_seconds", &tippe::SummaryWork::cpu_seconds);
  // dynamic_attr: each result also carries its `trajectory` (a dict of columns).
  py::class_<tippe::RunSummary>(m, "RunSummary", py::dynamic_attr())
      .def_readonly("format", &tippe::RunSummary::format)
      .def_readonly("scene", &tippe::RunSummary::scene)
      .def_readonly("scene_file", &tippe::RunSummary::scene_file)
      .def_readonly("scene_hash", &tippe::RunSummary::scene_hash)
      .def_readonly("engine", &tippe::RunSummary::engine)
      .def_readonly("engine_version", &tippe::RunSummary::engine_version)
      .def_readonly("status", &tippe::RunSummary::status)
      .def_readonly("status_time", &tippe::RunSummary::status_time)
      .def_readonly("status_detail", &tippe::RunSummary::status_detail)
      .def_readonly("inversion_time", &tippe::RunSummary::inversion_time)
      .def_readonly("stem_contact_time", &tippe::RunSummary::stem_contact_time)
      .def_readonly("samples", &tippe::RunSummary::samples)
      .def_readonly("final_time", &tippe::RunSummary::final_time)
      .def_readonly("final_tilt", &tippe::RunSummary::final_tilt)
      .def_readonly("energy_initial", &tippe::RunSummary::energy_initial)
      .def_readonly("energy_final", &tippe::RunSummary::energy_final)
      .def_readonly("jellett_initial", &tippe::RunSummary::jellett_initial)
      .def_readonly("jellett_max_relative_drift", &tippe::RunSummary::jellett_max_relative_drift)
      .def_readonly("jellett_drift_ball", &tippe::RunSummary::jellett_drift_ball)
      .def_readonly("jellett_drift_stem", &tippe::RunSummary::jellett_drift_stem)
      .def_readonly("min_normal_force", &tippe::RunSummary::min_normal_force)
      .def_readonly("mass_properties", &tippe::RunSummary::mass_properties)
      .def_readonly("inversion_possible", &tippe::RunSummary::inversion_possible)
      .def_readonly("work", &tippe::RunSummary::work)
      .def_readonly("events", &tippe::RunSummary::events)
      .def_readonly("settings", &tippe::RunSummary::settings)
      .def_readonly("notes", &tippe::RunSummary::notes)
      .def_readonly("json", &tippe::RunSummary::json, "the summary.json text")
      .def("__repr__", [](const tippe::RunSummary& s) {
        return "<RunSummary " + s.scene + " " + s.engine + " status=" + s.status + ">";
      });

  m.def(
      "run_scene_file",
      [](const std::string& path, const std::vector<std::string>& overrides) {
        tippe::TrajectoryColumns t;
        tippe::RunSummary s;
        {
          py::gil_scoped_release release;
          s = tippe::run_scene_file(path, overrides, &t);
        }
        return run(s, t);
      },
      py::arg("path"), py::arg("overrides") = std::vector<std::string>{},
      "Runs the analytic reference on a scene file (as `tippe run`); overrides are KEY=VALUE strings as for --set.");
  m.def(
      "run_scene",
      [](const py::dict& scene, const std::vector<std::string>& overrides) {
        const std::string text = scene_dict_to_toml(scene);
        tippe::TrajectoryColumns t;
        tippe::RunSummary s;
        {
          py::gil_scoped_release release;
          s = tippe::run_scene_text(text, "dict", overrides, &t);
        }
        return run(s, t);
      },
      py::arg("scene"), py::arg("overrides") = std::vector<std::string>{},
      "Runs the analytic reference on a scene given as a dict with a scene file's keys.");
}
