// `import nebula`: the render pipeline from Python (docs/python.md). Scenes
// load with overrides given as Python values; renders (fast or truth, CPU or
// CUDA) come back as numpy arrays with their metadata; a Session keeps its
// grids, bakes and tables so that a loop over parameters redoes only what
// changed (pipeline/render_session.h). Errors are nebula.Error (a ValueError)
// with the scene, key or argument named; a wrong Python type is a TypeError
// naming the key.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/gpu.h"
#include "imageio/image_output.h"
#include "montecarlo/tabulate.h"
#include "pipeline/render_session.h"
#include "pipeline/sweep.h"
#include "validation/image_compare.h"

namespace py = pybind11;
using namespace nebula;

namespace {

// A Python value as the TOML text an override takes ("KEY=VALUE").
std::string toml_value(const std::string& key, const py::handle& v) {
  if (py::isinstance<py::bool_>(v)) return v.cast<bool>() ? "true" : "false";
  if (py::isinstance<py::int_>(v)) return py::str(v).cast<std::string>();
  if (py::isinstance<py::float_>(v)) {
    const double x = v.cast<double>();
    if (!std::isfinite(x)) throw py::value_error(key + ": " + py::repr(v).cast<std::string>() + " is not a finite number");
    return to_text(x);
  }
  if (py::isinstance<py::str>(v)) {
    std::string out = "\"";
    for (char c : v.cast<std::string>()) {
      if (c == '"' || c == '\\') out += '\\';
      if (static_cast<unsigned char>(c) < 0x20) throw py::value_error(key + ": a control character in a string");
      out += c;
    }
    return out + "\"";
  }
  if (py::isinstance<py::dict>(v)) {
    std::string out = "{";
    bool first = true;
    for (auto item : v.cast<py::dict>()) {
      const std::string k = py::str(item.first).cast<std::string>();
      out += (first ? "" : ", ") + k + " = " + toml_value(key + "." + k, item.second);
      first = false;
    }
    return out + "}";
  }
  if (py::isinstance<py::list>(v) || py::isinstance<py::tuple>(v)) {
    std::string out = "[";
    bool first = true;
    for (auto item : v) {
      out += (first ? "" : ", ") + toml_value(key, item);
      first = false;
    }
    return out + "]";
  }
  if (py::hasattr(v, "__float__") && !py::isinstance<py::str>(v)) return toml_value(key, py::float_(py::reinterpret_borrow<py::object>(v)));
  throw py::type_error(key + ": a " + py::str(v.get_type().attr("__name__")).cast<std::string>() +
                       " is not a scene value (numbers, bool, str, lists and dicts are)");
}

std::vector<std::string> overrides_of(const py::object& set) {
  std::vector<std::string> out;
  if (set.is_none()) return out;
  if (!py::isinstance<py::dict>(set)) throw py::type_error("set: a dict of scene keys to values");
  for (auto item : set.cast<py::dict>()) {
    if (!py::isinstance<py::str>(item.first)) throw py::type_error("set: keys are scene keys as strings");
    const std::string key = item.first.cast<std::string>();
    out.push_back(key + "=" + toml_value(key, item.second));
  }
  return out;
}

Backend backend_of(const std::string& name) {
  if (name == "cpu") return Backend::Cpu;
  if (name == "cuda") return Backend::Cuda;
  if (name == "auto") return gpu_available() ? Backend::Cuda : Backend::Cpu;
  throw py::value_error("backend: '" + name + "' is not cpu, cuda or auto");
}

py::object meta_value(const MetaValue& v) {
  if (v.kind == MetaValue::Kind::Integer) return py::int_(v.integer);
  if (v.kind == MetaValue::Kind::Real) return py::float_(v.real);
  return py::str(v.text);
}

py::dict metadata_dict(const ImageMetadata& m) {
  py::dict d;
  d["units"] = m.units;
  d["exposure"] = m.exposure;
  for (const auto& [k, v] : m.entries) d[py::str(k)] = meta_value(v);
  if (!m.scene_text.empty()) d["scene_toml"] = m.scene_text;
  return d;
}

// What a front end reads of a run report: the timings and what was reused.
py::dict report_dict(const RunReport& r) {
  py::dict d;
  d["backend"] = to_string(r.backend);
  d["mode"] = r.mode;
  d["multiple_scattering"] = r.multiple_scattering;
  d["bake_seconds"] = r.bake.seconds;
  d["bake_reused"] = r.bake.reused;
  d["diffuse_seconds"] = r.diffuse.wall_seconds;
  d["diffuse_reused"] = r.diffuse.reused;
  d["diffuse_shared_with"] = r.diffuse.shared_with;
  d["render_seconds"] = r.render_seconds;
  d["star_pixels"] = r.star_pixels;  // the pixels at the stars' images (render.star_pixels)
  d["star_pixel_rays"] = r.star_pixel_rays;
  d["total_seconds"] = r.total_seconds;
  return d;
}

// A rendered image: planes (bands, rows, columns) in radiance, row 0 at the top.
struct PyImage {
  Image image;
  ImageMetadata metadata;
  py::dict report;
};

py::array_t<float> planes(const Image& image) {
  py::array_t<float> a({py::ssize_t(image.bands.size()), py::ssize_t(image.height), py::ssize_t(image.width)});
  std::copy(image.pixels.begin(), image.pixels.end(), a.mutable_data());
  return a;
}

Image image_of(const py::array_t<float, py::array::c_style | py::array::forcecast>& data,
               const std::vector<std::string>& bands) {
  if (data.ndim() != 3) throw py::value_error("data: an array of shape (bands, rows, columns)");
  if (size_t(data.shape(0)) != bands.size()) throw py::value_error("bands: one name per plane of data");
  Image image(int(data.shape(2)), int(data.shape(1)), bands);
  std::copy(data.data(), data.data() + data.size(), image.pixels.begin());
  return image;
}

// Runs `f` without the GIL, turning nebula errors into nebula.Error.
template <class F>
auto released(F f) {
  py::gil_scoped_release unlocked;
  return f();
}

class PySession {
 public:
  PySession(const std::string& scene, const py::object& set, const std::string& backend, double table_photons,
            bool is_text, const std::string& base_dir) {
    RenderOptions o;
    o.backend = backend_of(backend);
    if (!(table_photons >= 1000 && table_photons <= double(kMaxBasePhotons)))
      throw py::value_error("table_photons: must be 1000 to 2^25 (rows of tau_sct < 1 trace up to 32 times more)");
    o.table_photons = uint64_t(table_photons);
    const std::vector<std::string> overrides = overrides_of(set);
    session_ = std::make_unique<RenderSession>(
        released([&] {
          return is_text ? RenderSession::from_text(scene, "<text>", base_dir, overrides, o)
                         : RenderSession::from_file(scene, overrides, o);
        }));
  }

  std::string scene_toml(const py::object& set) {
    const std::vector<std::string> o = overrides_of(set);
    return released([&] { return session_->load(o).resolved_toml; });
  }

  PyImage render(const py::object& set) {
    const std::vector<std::string> o = overrides_of(set);
    RenderOutput out = released([&] { return session_->render(o); });
    return PyImage{std::move(out.image), std::move(out.metadata), report_dict(out.report)};
  }

  py::tuple truth(const py::object& set, int spp, uint64_t seed, bool equiangular) {
    const std::vector<std::string> o = overrides_of(set);
    TruthOptions t;
    t.backend = session_->options().backend;
    t.spp = spp;
    t.seed = seed;
    t.equiangular = equiangular;
    TruthRenderOutput out = released([&] { return session_->truth(o, t); });
    const py::dict report = report_dict(out.report);
    return py::make_tuple(PyImage{std::move(out.image), out.metadata, report},
                          PyImage{std::move(out.variance), out.variance_metadata, report});
  }

  py::dict sweep(const py::dict& grid, bool truth, int spp, uint64_t seed, bool force, bool share_photons) {
    std::vector<CubeAxis> axes;
    for (auto item : grid) {
      const std::string key = py::str(item.first).cast<std::string>();
      CubeAxis a{key, {}};
      if (!py::isinstance<py::sequence>(item.second) || py::isinstance<py::str>(item.second))
        throw py::type_error(key + ": a sequence of numbers to sweep");
      for (auto v : item.second) {
        if (!py::isinstance<py::float_>(v) && !py::isinstance<py::int_>(v) && !py::hasattr(v, "__float__"))
          throw py::type_error(key + ": " + py::repr(v).cast<std::string>() + " is not a number");
        a.values.push_back(py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>());
      }
      axes.push_back(std::move(a));
    }
    SweepOptions so;
    so.truth = truth;
    so.truth_options.backend = session_->options().backend;
    so.truth_options.spp = spp;
    so.truth_options.seed = seed;
    so.force = force;
    so.share_photons = share_photons;
    SweepResult r = released([&] { return run_sweep(*session_, axes, so); });
    std::vector<py::ssize_t> shape;
    for (const CubeAxis& a : r.axes) shape.push_back(py::ssize_t(a.values.size()));
    const Image& first = r.images.front();
    shape.insert(shape.end(), {py::ssize_t(first.bands.size()), py::ssize_t(first.height), py::ssize_t(first.width)});
    py::array_t<float> data(shape);
    float* at = data.mutable_data();
    for (const Image& image : r.images) at = std::copy(image.pixels.begin(), image.pixels.end(), at);
    py::dict out;
    out["data"] = data;
    py::list axis_list;
    for (const CubeAxis& a : r.axes) axis_list.append(py::make_tuple(a.key, py::array_t<double>(a.values.size(), a.values.data())));
    out["axes"] = axis_list;
    out["bands"] = first.bands;
    out["metadata"] = metadata_dict(r.metadata);
    py::list reports;
    for (const RunReport& rep : r.reports) reports.append(report_dict(rep));
    out["reports"] = reports;
    out["seconds"] = r.seconds;
    return out;
  }

 private:
  std::unique_ptr<RenderSession> session_;
};

py::dict tabulate_py(double albedo, double g, double photons_per_row, double tau_max, int tau_bins, int mu_bins,
                     uint64_t seed, const std::string& backend) {
  TabulateParams p;
  p.albedo = albedo;
  p.g = g;
  p.photons_per_row = uint64_t(photons_per_row);
  p.tau_max = tau_max;
  p.tau_bins = tau_bins;
  p.mu_bins = mu_bins;
  p.seed = seed;
  if (!(photons_per_row >= 1 && photons_per_row <= double(kMaxPhotonsPerRow)))
    throw py::value_error("photons_per_row: must be 1 to 2^30");
  const Backend b = backend_of(backend);
  const Tabulation t = released([&] {
    validate(p);
    return tabulate(p, b);
  });
  const AngularBins bins = t.bins();
  std::vector<double> mu(t.n_mu());
  for (int k = 0; k < t.n_mu(); ++k) mu[k] = bins.centre(k);
  auto grid = [&](const std::vector<double>& v) {
    py::array_t<double> a({py::ssize_t(t.n_tau()), py::ssize_t(t.n_mu())});
    std::copy(v.begin(), v.end(), a.mutable_data());
    return a;
  };
  py::dict d;
  d["tau"] = py::array_t<double>(t.tau.size(), t.tau.data());
  d["mu"] = py::array_t<double>(mu.size(), mu.data());
  d["P"] = grid(t.P);
  d["P_stderr"] = grid(t.P_stderr);
  d["total"] = py::array_t<double>(t.total.size(), t.total.data());
  d["unscattered"] = py::array_t<double>(t.unscattered.size(), t.unscattered.data());
  d["seconds"] = t.seconds;
  return d;
}

py::list compare_py(const PyImage& a, const PyImage& b, const py::object& variance, double signal_fraction) {
  const Image* var = nullptr;
  PyImage v;
  if (!variance.is_none()) {
    v = variance.cast<PyImage>();
    var = &v.image;
  }
  if (a.image.width != b.image.width || a.image.height != b.image.height || a.image.bands != b.image.bands)
    throw py::value_error("compare: the images differ in size or bands");
  const Comparison c = compare_images(a.image, b.image, nullptr, var, signal_fraction);
  py::list out;
  for (const BandComparison& bc : c.bands) {
    py::dict d;
    d["band"] = bc.band;
    d["signal_pixels"] = bc.signal_pixels;
    d["bias"] = bc.bias;
    d["bias_stderr"] = bc.bias_stderr;
    d["rel_l1"] = bc.rel_l1;
    d["rel_l2"] = bc.rel_l2;
    d["worst_1pct"] = bc.worst_1pct;
    if (bc.has_variance) {
      d["noise_rel_l2"] = bc.noise_rel_l2;
      d["rel_l2_excess"] = bc.rel_l2_excess;
      d["within_noise"] = bc.within_noise;
    }
    out.append(d);
  }
  return out;
}

}  // namespace

PYBIND11_MODULE(nebula, m) {
  m.doc() = "nebula: reflection-nebula rendering (fast renderer, ground truth, tables) from Python";
  static py::exception<Error> error(m, "Error", PyExc_ValueError);
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const Error& e) {
      error(e.what());
    }
  });

  py::class_<PyImage>(m, "Image", "a rendered image: data (bands, rows, columns) in solLum pc-2 sr-1, row 0 on top")
      .def(py::init([](const py::array_t<float, py::array::c_style | py::array::forcecast>& data,
                       const std::vector<std::string>& bands) { return PyImage{image_of(data, bands), {}, {}}; }),
           py::arg("data"), py::arg("bands"))
      .def_property_readonly("data", [](const PyImage& i) { return planes(i.image); })
      .def_property_readonly("bands", [](const PyImage& i) { return i.image.bands; })
      .def_property_readonly("width", [](const PyImage& i) { return i.image.width; })
      .def_property_readonly("height", [](const PyImage& i) { return i.image.height; })
      .def_property_readonly("metadata", [](const PyImage& i) { return metadata_dict(i.metadata); })
      .def_property_readonly("report", [](const PyImage& i) { return i.report; })
      .def("band", [](const PyImage& i, const std::string& name) {
             for (size_t b = 0; b < i.image.bands.size(); ++b)
               if (i.image.bands[b] == name) return planes(i.image)[py::int_(b)].cast<py::array_t<float>>();
             throw py::key_error("band '" + name + "' is not in this image");
           }, py::arg("name"), "one band's plane (rows, columns)")
      .def("write", [](const PyImage& i, const std::string& path, bool overwrite) {
             released([&] { write_image(i.image, path, i.metadata, overwrite); return 0; });
           }, py::arg("path"), py::arg("overwrite") = false, "to .fits, .h5 (and .exr/.png with OpenImageIO), atomically")
      .def("__repr__", [](const PyImage& i) {
        std::ostringstream s;
        s << "<nebula.Image " << i.image.width << "x" << i.image.height << " bands=";
        for (size_t b = 0; b < i.image.bands.size(); ++b) s << (b ? "," : "") << i.image.bands[b];
        return s.str() + ">";
      });

  py::class_<PySession>(m, "Session",
                        "a scene kept loaded: render(), truth() and sweep() redo only what their overrides change")
      .def(py::init([](const std::string& path, const py::object& set, const std::string& backend, double table_photons) {
             return std::make_unique<PySession>(path, set, backend, table_photons, false, "");
           }),
           py::arg("scene"), py::arg("set") = py::none(), py::arg("backend") = "auto", py::arg("table_photons") = 3e4,
           "open a scene file (TOML), with overrides {key: value} applied to everything it renders")
      .def_static("from_text", [](const std::string& text, const py::object& set, const std::string& backend,
                                  double table_photons, const std::string& base_dir) {
             return std::make_unique<PySession>(text, set, backend, table_photons, true, base_dir);
           },
           py::arg("text"), py::arg("set") = py::none(), py::arg("backend") = "auto", py::arg("table_photons") = 3e4,
           py::arg("base_dir") = ".", "a scene from TOML text")
      .def("scene_toml", &PySession::scene_toml, py::arg("set") = py::none(), "the resolved scene (TOML) under these overrides")
      .def("render", &PySession::render, py::arg("set") = py::none(), "the fast render under these overrides")
      .def("truth", &PySession::truth, py::arg("set") = py::none(), py::arg("spp") = 64, py::arg("seed") = 1,
           py::arg("equiangular") = false, "the ground truth: (mean, variance of the mean)")
      .def("sweep", &PySession::sweep, py::arg("grid"), py::arg("truth") = false, py::arg("spp") = 64,
           py::arg("seed") = 1, py::arg("force") = false, py::arg("share_photons") = true,
           "a grid {key: values, ...} (first key slowest): dict(data=(n1, ..., bands, rows, columns), axes, ...); "
           "share_photons: points differing only in albedo share one photon pass for their diffuse fields "
           "(False: each its own, equal to a separate render bit for bit)");

  m.def("tabulate", &tabulate_py, py::arg("albedo") = 0.6, py::arg("g") = 0.6, py::arg("photons_per_row") = 1e5,
        py::arg("tau_max") = 10.0, py::arg("tau_bins") = 100, py::arg("mu_bins") = 72, py::arg("seed") = 1,
        py::arg("backend") = "auto", "the Monte-Carlo table P(tau, mu) of one voxel (2005 paper, section 4.1)");
  m.def("compare", &compare_py, py::arg("image"), py::arg("reference"), py::arg("variance") = py::none(),
        py::arg("signal_fraction") = 1e-3,
        "per band: bias, relative L1/L2, and with the reference's variance the L2 beyond its noise");
  m.def("read_image", [](const std::string& path) {
          ImageMetadata meta;
          Image image = released([&] { return read_image(path, &meta); });
          return PyImage{std::move(image), std::move(meta), {}};
        }, py::arg("path"), "an image nebula wrote (.fits, .h5, .exr)");
}
