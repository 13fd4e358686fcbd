#include "scene/scene_file.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>
#include <utility>

#include "core/error.h"
#include "illumination/filter_file.h"
#include "illumination/star.h"
#include "scene/camera_path_toml.h"
#include "scene/display_toml.h"
#include "scene/scene_checks.h"

namespace nebula {
namespace {

namespace fs = std::filesystem;
using scene_detail::number_text;

std::string join(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\r', ' ');
  return s;
}

const char* type_name(const toml::node& n) {
  switch (n.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    default: return "nothing";
  }
}

// The keys of every table in a scene file.
const std::initializer_list<std::string_view> kTopKeys = {"bands",  "density", "emission", "dust",   "stars",
                                                          "camera", "output",  "render",   "axial",  "filters",
                                                          "spectral", "animation", "display"};
const std::initializer_list<std::string_view> kSpectralKeys = {
    "method", "basis", "wavelengths", "attenuation", "norm", "fit_depth", "max_depth", "range_um", "near_voxels",
    "tables", "table_nodes", "emission", "dust"};
const std::initializer_list<std::string_view> kSpectralDustKeys = {"wavelength_nm", "albedo", "g"};
const std::initializer_list<std::string_view> kSpectralEmissionKeys = {"line_nm", "continuum", "range_nm", "file",
                                                                       "dataset", "scale"};
const std::initializer_list<std::string_view> kRenderKeys = {
    "levels", "multiple_scattering", "diffuse_order", "diffuse_zonal", "diffuse_cells", "diffuse_photons", "diffuse_seed", "diffuse_taper",
    "samples_per_pixel", "star_pixels"};
const std::initializer_list<std::string_view> kAxialKeys = {
    "synthetic", "file", "image", "dataset", "emission_prefix", "tau_channel", "emission_channels", "nx", "nr",
    "length_pc", "tau_scale", "emission_scale", "origin", "axis", "skip", "step_texels", "colour_deform",
    "shape_deform"};
const std::initializer_list<std::string_view> kAxialNoiseKeys = {"kind",       "frequency", "octaves", "gain",
                                                                 "lacunarity", "amplitude", "seed"};
const std::initializer_list<std::string_view> kDensityKeys = {
    "file", "dataset", "fits", "voxel_size_pc", "procedural", "scale"};
const std::initializer_list<std::string_view> kProceduralKeys = {
    "n",             "size_pc",         "origin_pc",       "seed",           "star",
    "wind_direction", "bubble_offset",  "bubble_radius",   "bubble_tau",     "shell_thickness",
    "shell_tau",     "cloud_tau",       "scale_length",    "near_side",      "far_multiplier",
    "far_transition", "noise_amplitude", "noise_frequency", "noise_octaves", "noise_gain",
    "noise_lacunarity", "far_offset", "far_warp", "filament_amplitude", "filament_frequency",
    "filament_octaves", "filament_sharpness", "edge_fade"};
const std::initializer_list<std::string_view> kEmissionKeys = {"file", "prefix", "scale"};
const std::initializer_list<std::string_view> kDustKeys = {"albedo", "g", "R_V", "law", "tables"};
const std::initializer_list<std::string_view> kStarKeys = {"name", "position", "luminosity_lsun",
                                                           "temperature_K", "class"};
const std::initializer_list<std::string_view> kCameraKeys = {
    "kind", "position", "look_at", "up", "fov_deg", "ortho_width", "width", "height", "exposure"};
const std::initializer_list<std::string_view> kOutputKeys = {"file", "draw_stars",
                                                             "star_psf_pixels"};

enum class DensityKind { Hdf5, Fits, Procedural };

struct DensityPlan {
  DensityKind kind = DensityKind::Procedural;
  std::string key;   // "density.file", "density.fits" or "density.procedural"
  std::string path;  // resolved file
  std::string dataset = "tau_v";
  double voxel_size_pc = 0;
  ProceduralParams procedural;
  double scale = 1;
};

struct EmissionPlan {
  std::string path, prefix = "emission_";
  double scale = 1;  // multiplies every band's emission (the viewer's emission slider)
};

class Parser {
 public:
  Parser(std::string name, fs::path base_dir) : name_(std::move(name)), base_(std::move(base_dir)) {}

  [[noreturn]] void fail(const std::string& key, const std::string& reason) const {
    std::string message = name_ + ": " + key + ": " + reason;
    // The latest override touching this key (or a table around or inside it).
    for (auto it = overrides_.rbegin(); it != overrides_.rend(); ++it) {
      const std::string& k = it->first;
      const bool related = k == key || key.rfind(k + ".", 0) == 0 || k.rfind(key + ".", 0) == 0;
      if (related) {
        message += " (set by override '" + it->second + "')";
        break;
      }
    }
    throw Error(one_line(message));
  }

  // A conflict between top-level tables: blames only an override that made
  // one of `tables` (one the file itself lacks), never an unrelated one.
  [[noreturn]] void fail_tables(const std::string& key, const std::string& reason,
                                std::initializer_list<const char*> tables) const {
    std::string message = name_ + ": " + key + ": " + reason;
    bool blamed = false;
    for (const char* table : tables) {
      if (blamed || file_tables_.count(table) != 0) continue;
      const std::string t(table);
      for (auto it = overrides_.rbegin(); it != overrides_.rend() && !blamed; ++it)
        if (it->first == t || it->first.rfind(t + ".", 0) == 0) {
          message += " ([" + t + "] made by override '" + it->second + "')";
          blamed = true;
        }
    }
    throw Error(one_line(message));
  }

  // The top-level keys the file itself has, before any override.
  void note_file_tables(const toml::table& root) {
    for (auto&& [k, v] : root) {
      (void)v;
      file_tables_.insert(std::string(k.str()));
    }
  }

  void apply_override(toml::table& root, const std::string& text);
  Scene build(toml::table& root, const Scene* reuse_grids = nullptr);

 private:
  // ------------------------------------------------ typed access

  void known_keys(const toml::table& t, const std::string& path,
                  std::initializer_list<std::string_view> keys) const {
    for (auto&& [k, v] : t) {
      (void)v;
      const std::string_view name = k.str();
      if (std::find(keys.begin(), keys.end(), name) != keys.end()) continue;
      std::string list;
      for (std::string_view known : keys) list += (list.empty() ? "" : ", ") + std::string(known);
      fail(join(path, std::string(name)), "unknown key (known here: " + list + ")");
    }
  }

  const toml::table& table_at(const toml::node& n, const std::string& key) const {
    if (!n.is_table()) fail(key, std::string("must be a table, got ") + type_name(n));
    return *n.as_table();
  }

  double number(const toml::node& n, const std::string& key) const {
    double v;
    if (n.is_integer())
      v = static_cast<double>(n.as_integer()->get());
    else if (n.is_floating_point())
      v = n.as_floating_point()->get();
    else
      fail(key, std::string("must be a number, got ") + type_name(n));
    if (!std::isfinite(v)) fail(key, "must be finite, got " + number_text(v));
    return v;
  }

  int64_t integer(const toml::node& n, const std::string& key) const {
    if (!n.is_integer()) fail(key, std::string("must be an integer, got ") + type_name(n));
    return n.as_integer()->get();
  }

  int small_integer(const toml::node& n, const std::string& key) const {
    const int64_t v = integer(n, key);
    if (v < std::numeric_limits<int>::min() || v > std::numeric_limits<int>::max())
      fail(key, "is " + std::to_string(v) + ", out of range");
    return static_cast<int>(v);
  }

  bool boolean(const toml::node& n, const std::string& key) const {
    if (!n.is_boolean()) fail(key, std::string("must be true or false, got ") + type_name(n));
    return n.as_boolean()->get();
  }

  std::string string(const toml::node& n, const std::string& key) const {
    if (!n.is_string()) fail(key, std::string("must be a string, got ") + type_name(n));
    return n.as_string()->get();
  }

  Vec3 vec3(const toml::node& n, const std::string& key) const {
    const toml::array* a = n.as_array();
    if (a == nullptr || a->size() != 3)
      fail(key, std::string("must be an array of 3 numbers [x, y, z], got ") +
                    (a ? "an array of " + std::to_string(a->size()) : std::string(type_name(n))));
    double c[3];
    for (int i = 0; i < 3; ++i) {
      c[i] = number((*a)[size_t(i)], key + "[" + std::to_string(i) + "]");
      if (std::fabs(c[i]) > 1e30) fail(key, "component " + number_text(c[i]) + " is too large");
    }
    return Vec3{float(c[0]), float(c[1]), float(c[2])};
  }

  // A data file named by `key`, resolved against the scene's folder.
  std::string data_path(const toml::node& n, const std::string& key) const {
    const std::string text = string(n, key);
    if (text.empty()) fail(key, "must name a file");
    fs::path p(text);
    if (p.is_relative()) p = base_ / p;
    return p.lexically_normal().string();
  }

  // One value for every band, or a table {B = .., V = .., R = ..} naming each band.
  std::vector<double> per_band(const toml::node& n, const std::string& key,
                               const std::vector<std::string>& bands) const {
    if (!n.is_table()) return std::vector<double>(bands.size(), number(n, key));
    const toml::table& t = *n.as_table();
    for (auto&& [k, v] : t) {
      (void)v;
      const std::string band(k.str());
      if (std::find(bands.begin(), bands.end(), band) == bands.end())
        fail(join(key, band), "unknown band (the scene's bands: " + band_list(bands) + ")");
    }
    std::vector<double> values;
    for (const std::string& band : bands) {
      const toml::node* v = t.get(band);
      if (v == nullptr) fail(join(key, band), "missing: a per-band table must give every band");
      values.push_back(number(*v, join(key, band)));
    }
    return values;
  }

  static std::string band_list(const std::vector<std::string>& bands) {
    std::string list;
    for (const std::string& b : bands) list += (list.empty() ? "" : ", ") + b;
    return list;
  }

  // ------------------------------------------------ sections

  std::vector<std::string> parse_bands(const toml::table& root, const std::vector<SceneFilter>& filters) const;
  std::vector<SceneFilter> parse_filters(const toml::table& root) const;
  std::optional<SpectralSpec> parse_spectral(const toml::table& root) const;
  DensityPlan parse_density(const toml::table& root) const;
  AxialSpec parse_axial(const toml::table& root, const std::vector<std::string>& bands) const;
  void parse_axial_noise(const toml::table& axial, const char* name, bool shape, AxialNoiseSpec& out) const;
  ProceduralParams parse_procedural(const toml::table& t, const std::string& key) const;
  std::optional<EmissionPlan> parse_emission(const toml::table& root) const;
  DustParams parse_dust(const toml::table& root, const std::vector<std::string>& bands) const;
  std::vector<SceneStar> parse_stars(const toml::table& root, const DensityPlan& density) const;
  CameraSettings parse_camera(const toml::table& root) const;
  void parse_output(const toml::table& root, Scene& scene) const;
  void parse_render(const toml::table& root, Scene& scene) const;
  void load_spectral_emission(Scene& scene) const;
  void load_grids(const DensityPlan& density, const std::optional<EmissionPlan>& emission,
                  Scene& scene) const;

  std::string name_;
  fs::path base_;
  std::vector<std::pair<std::string, std::string>> overrides_;  // key path, "KEY=VALUE"
  std::set<std::string> file_tables_;
};

// ------------------------------------------------------------ overrides

void Parser::apply_override(toml::table& root, const std::string& text) {
  const size_t eq = text.find('=');
  if (eq == std::string::npos || eq == 0)
    throw Error(one_line(name_ + ": override '" + text + "': expected KEY=VALUE (e.g. camera.fov_deg=30)"));
  const std::string key = text.substr(0, eq), value = text.substr(eq + 1);
  std::vector<std::string> parts;
  for (size_t begin = 0;;) {
    const size_t dot = key.find('.', begin);
    parts.push_back(key.substr(begin, dot == std::string::npos ? std::string::npos : dot - begin));
    if (dot == std::string::npos) break;
    begin = dot + 1;
  }
  for (const std::string& part : parts)
    if (part.empty() || part.find_first_of(" \t\"'[]") != std::string::npos)
      throw Error(name_ + ": override '" + text + "': bad key '" + key +
                  "' (dotted names and 0-based indices, e.g. stars.0.luminosity_lsun)");
  if (value.find_first_of("\n\r") != std::string::npos)
    throw Error(name_ + ": override '" + key + "': the value must be one line");
  overrides_.emplace_back(key, text);

  // The value as TOML; text that is not a TOML value is a string.
  toml::table holder;
  try {
    const std::string document = "v = " + value;
    holder = toml::parse(std::string_view(document), std::string_view("override"));
  } catch (const toml::parse_error&) {
    holder = toml::table{};
    holder.insert_or_assign("v", value);
  }
  toml::node& parsed = *holder.get("v");

  toml::node* here = &root;
  std::string path;
  for (size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    const bool last = i + 1 == parts.size();
    const std::string at = join(path, part);
    if (toml::table* t = here->as_table()) {
      if (last) {
        parsed.visit([&](auto& v) { t->insert_or_assign(part, std::move(v)); });
        return;
      }
      toml::node* next = t->get(part);
      if (next == nullptr) {
        t->insert_or_assign(part, toml::table{});
        next = t->get(part);
      }
      here = next;
    } else if (toml::array* a = here->as_array()) {
      if (part.find_first_not_of("0123456789") != std::string::npos)
        fail(at, path + " is an array: address its elements by a 0-based index");
      size_t index = 0;
      try {
        index = std::stoul(part);
      } catch (const std::exception&) {
        fail(at, "index out of range");
      }
      if (index > a->size())
        fail(at, "index out of range: " + path + " has " + std::to_string(a->size()) +
                     " elements (index " + std::to_string(a->size()) + " appends one)");
      if (last) {
        if (index == a->size())
          parsed.visit([&](auto& v) { a->push_back(std::move(v)); });
        else
          parsed.visit([&](auto& v) { a->replace(a->cbegin() + std::ptrdiff_t(index), std::move(v)); });
        return;
      }
      if (index == a->size()) a->push_back(toml::table{});
      here = a->get(index);
    } else {
      fail(path, std::string("is ") + type_name(*here) + ", not a table: cannot set " + key);
    }
    path = at;
  }
}

// ------------------------------------------------------------ sections

std::vector<SceneFilter> Parser::parse_filters(const toml::table& root) const {
  std::vector<SceneFilter> filters;
  const toml::node* n = root.get("filters");
  if (n == nullptr) return filters;
  const toml::table& t = table_at(*n, "filters");
  for (auto&& [k, v] : t) {
    SceneFilter f;
    f.name = std::string(k.str());
    const std::string key = "filters." + f.name;
    f.path = data_path(v, key);
    try {
      f.passband = load_filter_file(f.path);
    } catch (const Error& e) {
      fail(key, e.what());
    }
    filters.push_back(std::move(f));
  }
  return filters;
}

std::optional<SpectralSpec> Parser::parse_spectral(const toml::table& root) const {
  const toml::node* n = root.get("spectral");
  if (n == nullptr) return std::nullopt;
  const toml::table& t = table_at(*n, "spectral");
  known_keys(t, "spectral", kSpectralKeys);
  SpectralSpec p;
  if (const toml::node* v = t.get("method")) p.method = lower(string(*v, "spectral.method"));
  if (const toml::node* v = t.get("basis")) p.basis = small_integer(*v, "spectral.basis");
  if (const toml::node* v = t.get("wavelengths")) p.wavelengths = small_integer(*v, "spectral.wavelengths");
  if (const toml::node* v = t.get("attenuation")) p.attenuation = lower(string(*v, "spectral.attenuation"));
  if (const toml::node* v = t.get("norm")) p.norm = lower(string(*v, "spectral.norm"));
  if (const toml::node* v = t.get("fit_depth")) p.fit_depth = number(*v, "spectral.fit_depth");
  if (const toml::node* v = t.get("max_depth")) p.max_depth = number(*v, "spectral.max_depth");
  if (const toml::node* v = t.get("near_voxels")) p.near_voxels = number(*v, "spectral.near_voxels");
  if (const toml::node* v = t.get("tables")) p.tables = boolean(*v, "spectral.tables");
  if (const toml::node* v = t.get("table_nodes")) p.table_nodes = small_integer(*v, "spectral.table_nodes");
  if (const toml::node* v = t.get("range_um")) {
    const toml::array* a = v->as_array();
    if (a == nullptr || a->size() != 2)
      fail("spectral.range_um", "must be an array of 2 numbers [lo, hi] in um");
    p.range_lo_um = number((*a)[0], "spectral.range_um[0]");
    p.range_hi_um = number((*a)[1], "spectral.range_um[1]");
  }
  if (const toml::node* v = t.get("dust")) {
    const toml::table& d = table_at(*v, "spectral.dust");
    known_keys(d, "spectral.dust", kSpectralDustKeys);
    const auto numbers = [&](const char* name, std::vector<double>& out) {
      const std::string key = std::string("spectral.dust.") + name;
      const toml::node* n = d.get(name);
      if (n == nullptr) return;
      const toml::array* a = n->as_array();
      if (a == nullptr || a->empty() || a->size() > 64) fail(key, "must be an array of 1 to 64 numbers");
      for (size_t k = 0; k < a->size(); ++k) out.push_back(number((*a)[k], key + "[" + std::to_string(k) + "]"));
    };
    numbers("wavelength_nm", p.dust_nm);
    numbers("albedo", p.dust_albedo);
    numbers("g", p.dust_g);
    if (p.dust_nm.empty()) fail("spectral.dust.wavelength_nm", "is required: the wavelengths of the albedo and g values");
    if (p.dust_albedo.empty() && p.dust_g.empty()) fail("spectral.dust", "give albedo, g or both at wavelength_nm");
    for (const auto& [name, values] : {std::pair<const char*, const std::vector<double>*>{"albedo", &p.dust_albedo},
                                       std::pair<const char*, const std::vector<double>*>{"g", &p.dust_g}})
      if (!values->empty() && values->size() != p.dust_nm.size())
        fail(std::string("spectral.dust.") + name, std::to_string(values->size()) + " values for " +
                                                       std::to_string(p.dust_nm.size()) + " wavelengths");
  }
  if (const toml::node* v = t.get("emission")) {
    const toml::array* a = v->as_array();
    if (a == nullptr) fail("spectral.emission", "must be an array of tables ([[spectral.emission]])");
    if (a->size() > size_t(kMaxSpectralEmission))
      fail("spectral.emission", std::to_string(a->size()) + " components; at most " +
                                    std::to_string(kMaxSpectralEmission));
    for (size_t i = 0; i < a->size(); ++i) {
      const std::string key = "spectral.emission." + std::to_string(i);
      const toml::table& e = table_at((*a)[i], key);
      known_keys(e, key, kSpectralEmissionKeys);
      SpectralEmissionSpec c;
      const toml::node* line = e.get("line_nm");
      const toml::node* continuum = e.get("continuum");
      if ((line == nullptr) == (continuum == nullptr))
        fail(key, "give exactly one of line_nm (a line) and continuum (polynomial coefficients)");
      if (line) c.line_nm = number(*line, key + ".line_nm");
      if (continuum) {
        const toml::array* coefficients = continuum->as_array();
        if (coefficients == nullptr || coefficients->empty() || coefficients->size() > 8)
          fail(key + ".continuum", "must be an array of 1 to 8 numbers (c_0, c_1, ... of sum c_k lambda^k, lambda in um)");
        for (size_t k = 0; k < coefficients->size(); ++k)
          c.continuum.push_back(number((*coefficients)[k], key + ".continuum[" + std::to_string(k) + "]"));
      }
      if (const toml::node* r = e.get("range_nm")) {
        const toml::array* range = r->as_array();
        if (range == nullptr || range->size() != 2) fail(key + ".range_nm", "must be an array of 2 numbers [lo, hi] in nm");
        if (line) fail(key + ".range_nm", "applies to a continuum; a line has no range");
        c.lo_nm = number((*range)[0], key + ".range_nm[0]");
        c.hi_nm = number((*range)[1], key + ".range_nm[1]");
      }
      if (const toml::node* f = e.get("file")) c.file = data_path(*f, key + ".file");
      if (const toml::node* d = e.get("dataset")) c.dataset = string(*d, key + ".dataset");
      if (c.file.empty() != c.dataset.empty())
        fail(key, "file and dataset go together (the weight grid); leave both out to weight by the voxel's tau_V");
      if (const toml::node* sc = e.get("scale")) c.scale = number(*sc, key + ".scale");
      p.emission.push_back(std::move(c));
    }
  }
  return p;
}

std::vector<std::string> Parser::parse_bands(const toml::table& root, const std::vector<SceneFilter>& filters) const {
  const toml::node* n = root.get("bands");
  if (n == nullptr) return {"B", "V", "R"};
  const toml::array* a = n->as_array();
  if (a == nullptr) fail("bands", std::string("must be an array of band names, got ") + type_name(*n));
  std::vector<std::string> bands;
  for (size_t i = 0; i < a->size(); ++i) bands.push_back(string((*a)[i], "bands[" + std::to_string(i) + "]"));
  if (bands.empty()) fail("bands", "must name at least one band");
  for (size_t i = 0; i < bands.size(); ++i) {
    if (auto issue = scene_detail::band_issue(bands[i], filters)) fail(issue->key, issue->reason);
    for (size_t j = 0; j < i; ++j)
      if (bands[j] == bands[i]) fail("bands", "'" + bands[i] + "' appears twice");
  }
  return bands;
}

ProceduralParams Parser::parse_procedural(const toml::table& t, const std::string& key) const {
  known_keys(t, key, kProceduralKeys);
  ProceduralParams p;
  auto num = [&](const char* name, double& out) {
    if (const toml::node* n = t.get(name)) out = number(*n, join(key, name));
  };
  auto vec = [&](const char* name, Vec3& out) {
    if (const toml::node* n = t.get(name)) out = vec3(*n, join(key, name));
  };
  auto small = [&](const char* name, int& out) {
    if (const toml::node* n = t.get(name)) out = small_integer(*n, join(key, name));
  };
  small("n", p.n);
  num("size_pc", p.size_pc);
  vec("origin_pc", p.origin_pc);
  if (const toml::node* n = t.get("seed")) {
    const int64_t seed = integer(*n, join(key, "seed"));
    if (seed < 0) fail(join(key, "seed"), "is " + std::to_string(seed) + "; must be >= 0");
    p.seed = static_cast<uint64_t>(seed);
  }
  vec("star", p.star);
  vec("wind_direction", p.wind_direction);
  num("bubble_offset", p.bubble_offset);
  num("bubble_radius", p.bubble_radius);
  num("bubble_tau", p.bubble_tau);
  num("shell_thickness", p.shell_thickness);
  num("shell_tau", p.shell_tau);
  num("cloud_tau", p.cloud_tau);
  num("scale_length", p.scale_length);
  vec("near_side", p.near_side);
  num("far_multiplier", p.far_multiplier);
  num("far_transition", p.far_transition);
  num("noise_amplitude", p.noise_amplitude);
  num("noise_frequency", p.noise_frequency);
  small("noise_octaves", p.noise_octaves);
  num("noise_gain", p.noise_gain);
  num("noise_lacunarity", p.noise_lacunarity);
  num("far_offset", p.far_offset);
  num("far_warp", p.far_warp);
  num("filament_amplitude", p.filament_amplitude);
  num("filament_frequency", p.filament_frequency);
  small("filament_octaves", p.filament_octaves);
  num("filament_sharpness", p.filament_sharpness);
  num("edge_fade", p.edge_fade);
  if (const auto issue = check_procedural(p)) fail(join(key, issue->parameter), issue->reason);
  return p;
}

DensityPlan Parser::parse_density(const toml::table& root) const {
  const toml::node* n = root.get("density");
  if (n == nullptr)
    fail("density", "missing required table [density] (one of file, fits or procedural)");
  const toml::table& t = table_at(*n, "density");
  known_keys(t, "density", kDensityKeys);
  std::vector<std::string> given;
  for (const char* source : {"file", "fits", "procedural"})
    if (t.get(source) != nullptr) given.push_back(source);
  if (given.empty()) fail("density", "give one of file (HDF5), fits or procedural");
  if (given.size() > 1)
    fail("density." + given[1], "conflicts with density." + given[0] +
                                    ": give exactly one of file, fits or procedural");
  DensityPlan plan;
  plan.key = "density." + given[0];
  if (given[0] == "procedural") {
    plan.kind = DensityKind::Procedural;
    plan.procedural = parse_procedural(table_at(*t.get("procedural"), plan.key), plan.key);
  } else {
    plan.kind = given[0] == "file" ? DensityKind::Hdf5 : DensityKind::Fits;
    plan.path = data_path(*t.get(given[0]), plan.key);
  }
  if (const toml::node* d = t.get("dataset")) {
    if (plan.kind != DensityKind::Hdf5) fail("density.dataset", "applies to density.file (HDF5) only");
    plan.dataset = string(*d, "density.dataset");
    if (plan.dataset.empty()) fail("density.dataset", "must not be empty");
  }
  if (const toml::node* v = t.get("voxel_size_pc")) {
    if (plan.kind != DensityKind::Fits)
      fail("density.voxel_size_pc",
           "applies to density.fits only (HDF5 files carry a voxel_size attribute; "
           "procedural grids use size_pc / n)");
    plan.voxel_size_pc = number(*v, "density.voxel_size_pc");
    if (!(plan.voxel_size_pc > 0))
      fail("density.voxel_size_pc", "is " + number_text(plan.voxel_size_pc) + "; must be > 0 (parsecs)");
  }
  if (const toml::node* s = t.get("scale")) {
    plan.scale = number(*s, "density.scale");
    if (!(plan.scale > 0)) fail("density.scale", "is " + number_text(plan.scale) + "; must be > 0");
  }
  return plan;
}

AxialSpec Parser::parse_axial(const toml::table& root, const std::vector<std::string>& bands) const {
  const toml::table& t = table_at(*root.get("axial"), "axial");
  known_keys(t, "axial", kAxialKeys);
  std::vector<std::string> given;
  for (const char* source : {"synthetic", "file", "image"})
    if (t.get(source) != nullptr) given.push_back(source);
  if (given.empty()) fail("axial", "give one of synthetic (a built-in map), file (HDF5) or image");
  if (given.size() > 1)
    fail("axial." + given[1], "conflicts with axial." + given[0] + ": give exactly one of synthetic, file or image");
  AxialSpec a;
  a.source = given[0];
  auto only = [&](const char* key, const char* source) {
    if (t.get(key) != nullptr && a.source != source)
      fail(std::string("axial.") + key, std::string("applies to axial.") + source + " only");
  };
  only("dataset", "file");
  only("emission_prefix", "file");
  only("tau_channel", "image");
  only("emission_channels", "image");
  only("nx", "synthetic");
  only("nr", "synthetic");
  if (a.source == "synthetic") {
    a.synthetic = string(*t.get("synthetic"), "axial.synthetic");
    const char* names[] = {"bipolar", "lopsided", "shells", "empty", "full", "cloud"};
    if (std::find_if(std::begin(names), std::end(names), [&](const char* n) { return a.synthetic == n; }) ==
        std::end(names))
      fail("axial.synthetic", "'" + a.synthetic + "' is not a built-in map (known: bipolar, lopsided, shells, empty, full, cloud)");
    for (const char* key : {"nx", "nr"})
      if (const toml::node* v = t.get(key)) {
        const int n = small_integer(*v, std::string("axial.") + key);
        if (n < 2 || n > 65536) fail(std::string("axial.") + key, "is " + std::to_string(n) + "; must be 2 to 65536");
        (std::string(key) == "nx" ? a.nx : a.nr) = n;
      }
  } else {
    a.path = data_path(*t.get(a.source), "axial." + a.source);
    std::ifstream probe(a.path, std::ios::binary);
    if (!probe || fs::is_directory(a.path)) fail("axial." + a.source, "cannot read '" + a.path + "'");
  }
  if (const toml::node* v = t.get("dataset")) {
    a.dataset = string(*v, "axial.dataset");
    if (a.dataset.empty()) fail("axial.dataset", "must not be empty");
  }
  if (const toml::node* v = t.get("emission_prefix")) a.emission_prefix = string(*v, "axial.emission_prefix");
  if (const toml::node* v = t.get("tau_channel")) {
    a.tau_channel = string(*v, "axial.tau_channel");
    if (a.tau_channel.empty()) fail("axial.tau_channel", "must name a channel");
  }
  if (const toml::node* v = t.get("emission_channels")) {
    const toml::table& ch = table_at(*v, "axial.emission_channels");
    a.emission_channels.assign(bands.size(), "");
    for (auto&& [k, value] : ch) {
      const std::string band(k.str());
      const auto at = std::find(bands.begin(), bands.end(), band);
      if (at == bands.end())
        fail("axial.emission_channels." + band, "unknown band (the scene's bands: " + band_list(bands) + ")");
      a.emission_channels[size_t(at - bands.begin())] = string(value, "axial.emission_channels." + band);
    }
  }
  auto positive = [&](const char* key, double& out, bool zero_ok) {
    if (const toml::node* v = t.get(key)) {
      out = number(*v, std::string("axial.") + key);
      if (!(out > 0 || (zero_ok && out == 0)))
        fail(std::string("axial.") + key, "is " + number_text(out) + (zero_ok ? "; must be >= 0" : "; must be > 0"));
    }
  };
  positive("length_pc", a.length_pc, false);
  positive("tau_scale", a.tau_scale, false);
  positive("emission_scale", a.emission_scale, true);
  positive("step_texels", a.step_texels, false);
  if (a.step_texels < 1e-3) fail("axial.step_texels", "is " + number_text(a.step_texels) + "; must be at least 1e-3");
  if (const toml::node* v = t.get("origin")) a.origin = vec3(*v, "axial.origin");
  if (const toml::node* v = t.get("axis")) {
    const Vec3 d = vec3(*v, "axial.axis");
    const double n = std::sqrt(double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z);
    if (!(n > 1e-12)) fail("axial.axis", "must not be zero (a direction)");
    a.axis = Vec3{float(d.x / n), float(d.y / n), float(d.z / n)};
  }
  if (const toml::node* v = t.get("skip")) {
    a.skip = string(*v, "axial.skip");
    const char* modes[] = {"naive",    "empty",           "global_max",         "omega",
                           "omega_multi", "distance",     "thesis_omega_max",   "thesis_omega_large",
                           "thesis_omega_multi"};
    if (std::find_if(std::begin(modes), std::end(modes), [&](const char* m) { return a.skip == m; }) == std::end(modes))
      fail("axial.skip", "'" + a.skip +
                             "' is not a skip mode (known: naive, empty, global_max, omega, omega_multi, distance, "
                             "thesis_omega_max, thesis_omega_large, thesis_omega_multi)");
  }
  parse_axial_noise(t, "colour_deform", false, a.colour_deform);
  parse_axial_noise(t, "shape_deform", true, a.shape_deform);
  return a;
}

// [axial.colour_deform] / [axial.shape_deform]: the table's presence turns
// the deformation on; each key checked against axial/axial_deform.h's ranges.
void Parser::parse_axial_noise(const toml::table& axial, const char* name, bool shape, AxialNoiseSpec& n) const {
  const toml::node* node = axial.get(name);
  if (node == nullptr) return;
  const std::string key = std::string("axial.") + name;
  const toml::table& t = table_at(*node, key);
  known_keys(t, key, kAxialNoiseKeys);
  n.on = true;
  if (const toml::node* v = t.get("kind")) {
    n.kind = string(*v, key + ".kind");
    if (n.kind != "simplex" && n.kind != "fbm" && n.kind != "turbulence" && n.kind != "cellular")
      fail(key + ".kind", "'" + n.kind + "' is not a noise kind (known: simplex, fbm, turbulence, cellular)");
  }
  auto real = [&](const char* k, double& out) {
    if (const toml::node* v = t.get(k)) out = number(*v, key + "." + k);
  };
  real("frequency", n.frequency);
  real("gain", n.gain);
  real("lacunarity", n.lacunarity);
  real("amplitude", n.amplitude);
  if (!(n.frequency > 0) || n.frequency > 1e6)
    fail(key + ".frequency", "is " + number_text(n.frequency) + "; must be > 0 (and at most 1e6 per map length)");
  if (!(n.gain > 0 && n.gain <= 1)) fail(key + ".gain", "is " + number_text(n.gain) + "; must be in (0, 1]");
  if (!(n.lacunarity >= 1) || n.lacunarity > 16)
    fail(key + ".lacunarity", "is " + number_text(n.lacunarity) + "; must be 1 to 16");
  const double top = shape ? 0.9 : 1.0;
  if (!(n.amplitude >= 0 && n.amplitude <= top))
    fail(key + ".amplitude", "is " + number_text(n.amplitude) + "; must be in [0, " + (shape ? "0.9" : "1") + "]" +
                                 (shape ? " (the largest pull towards the axis, a fraction of the distance)"
                                        : " (the largest lowering of emission and extinction)"));
  if (const toml::node* v = t.get("octaves")) {
    n.octaves = small_integer(*v, key + ".octaves");
    if (n.octaves < 1 || n.octaves > 8) fail(key + ".octaves", "is " + std::to_string(n.octaves) + "; must be 1 to 8");
  }
  if (const toml::node* v = t.get("seed")) {
    const int64_t seed = integer(*v, key + ".seed");
    if (seed < 0 || seed > 4294967295LL)
      fail(key + ".seed", "is " + std::to_string(seed) + "; must be 0 to 4294967295");
    n.seed = static_cast<uint32_t>(seed);
  }
}

std::optional<EmissionPlan> Parser::parse_emission(const toml::table& root) const {
  const toml::node* n = root.get("emission");
  if (n == nullptr) return std::nullopt;
  const toml::table& t = table_at(*n, "emission");
  known_keys(t, "emission", kEmissionKeys);
  EmissionPlan plan;
  if (const toml::node* v = t.get("scale")) {
    plan.scale = number(*v, "emission.scale");
    if (!(plan.scale >= 0) || !std::isfinite(plan.scale))
      fail("emission.scale", "is " + number_text(plan.scale) + "; must be >= 0 and finite");
  }
  const toml::node* file = t.get("file");
  if (file == nullptr) fail("emission.file", "missing required key (an HDF5 file)");
  plan.path = data_path(*file, "emission.file");
  if (const toml::node* p = t.get("prefix")) plan.prefix = string(*p, "emission.prefix");
  return plan;
}

DustParams Parser::parse_dust(const toml::table& root, const std::vector<std::string>& bands) const {
  DustParams dust;
  dust.albedo.assign(bands.size(), 0.6);
  dust.g.assign(bands.size(), 0.6);
  dust.table_files.assign(bands.size(), "");
  const toml::node* n = root.get("dust");
  if (n == nullptr) return dust;
  const toml::table& t = table_at(*n, "dust");
  known_keys(t, "dust", kDustKeys);
  if (const toml::node* a = t.get("albedo")) dust.albedo = per_band(*a, "dust.albedo", bands);
  if (const toml::node* g = t.get("g")) dust.g = per_band(*g, "dust.g", bands);
  if (const toml::node* r = t.get("R_V")) dust.R_V = number(*r, "dust.R_V");
  if (const toml::node* l = t.get("law")) {
    const std::string law = string(*l, "dust.law");
    if (lower(law) == "ccm89")
      dust.law = ExtinctionLaw::CCM89;
    else if (lower(law) == "odonnell94")
      dust.law = ExtinctionLaw::ODonnell94;
    else if (lower(law) == "grey" || lower(law) == "gray")
      dust.law = ExtinctionLaw::Grey;
    else
      fail("dust.law", "'" + law + "' is not a known law (known: ccm89, odonnell94, grey)");
  }
  if (const toml::node* tb = t.get("tables")) {
    const toml::table& tables = table_at(*tb, "dust.tables");
    for (auto&& [k, v] : tables) {
      const std::string band(k.str());
      const auto at = std::find(bands.begin(), bands.end(), band);
      const std::string key = "dust.tables." + band;
      if (at == bands.end()) fail(key, "unknown band (the scene's bands: " + band_list(bands) + ")");
      const std::string text = string(v, key);
      if (text.empty()) continue;  // generate on first use
      const std::string path = data_path(v, key);
      std::ifstream probe(path, std::ios::binary);
      if (!probe || fs::is_directory(path))
        fail(key, "cannot read the table file '" + path + "'");
      dust.table_files[size_t(at - bands.begin())] = path;
    }
  }
  return dust;
}

std::vector<SceneStar> Parser::parse_stars(const toml::table& root, const DensityPlan& density) const {
  std::vector<SceneStar> stars;
  const toml::node* n = root.get("stars");
  if (n == nullptr) return stars;
  const toml::array* a = n->as_array();
  if (a == nullptr)
    fail("stars", std::string("must be an array of tables ([[stars]] sections), got ") + type_name(*n));
  for (size_t i = 0; i < a->size(); ++i) {
    const std::string key = "stars." + std::to_string(i);
    const toml::table& t = table_at((*a)[i], key);
    known_keys(t, key, kStarKeys);
    SceneStar star;
    star.name = "star " + std::to_string(i);
    if (const toml::node* v = t.get("name")) star.name = string(*v, key + ".name");
    if (const toml::node* v = t.get("position")) {
      star.position = vec3(*v, key + ".position");
    } else if (density.kind == DensityKind::Procedural) {
      star.position = procedural_star_position(density.procedural);
    } else {
      fail(key + ".position", "missing required key (parsecs; it may be left out only with a "
                              "procedural density, whose star it then is)");
    }
    const toml::node* lum = t.get("luminosity_lsun");
    if (lum == nullptr) fail(key + ".luminosity_lsun", "missing required key (luminosity in L_sun)");
    star.luminosity_lsun = number(*lum, key + ".luminosity_lsun");
    if (!(star.luminosity_lsun > 0))
      fail(key + ".luminosity_lsun", "is " + number_text(star.luminosity_lsun) + "; must be > 0");
    const toml::node* temperature = t.get("temperature_K");
    const toml::node* cls = t.get("class");
    if (temperature == nullptr && cls == nullptr)
      fail(key, "give temperature_K or class (e.g. class = \"O5V\")");
    if (cls != nullptr) {
      star.spectral_class = string(*cls, key + ".class");
      try {
        star.temperature_K = effective_temperature_K(star.spectral_class);
      } catch (const Error& e) {
        fail(key + ".class", e.what());
      }
    }
    if (temperature != nullptr) {
      star.temperature_K = number(*temperature, key + ".temperature_K");
      if (!(star.temperature_K > 0))
        fail(key + ".temperature_K", "is " + number_text(star.temperature_K) + "; must be > 0 (K)");
    }
    stars.push_back(star);
  }
  return stars;
}

CameraSettings Parser::parse_camera(const toml::table& root) const {
  const toml::node* n = root.get("camera");
  if (n == nullptr) fail("camera", "missing required table [camera] (position and look_at)");
  const toml::table& t = table_at(*n, "camera");
  known_keys(t, "camera", kCameraKeys);
  CameraSettings c = scene_camera_defaults();
  if (const toml::node* k = t.get("kind"))
    if (!parse_projection(lower(string(*k, "camera.kind")), c.projection))
      fail("camera.kind", "'" + string(*k, "camera.kind") +
                              "' is not a camera kind (known: perspective, orthographic, fisheye)");
  for (const char* required : {"position", "look_at"})
    if (t.get(required) == nullptr)
      fail(std::string("camera.") + required, "missing required key ([x, y, z] in parsecs)");
  c.position = vec3(*t.get("position"), "camera.position");
  c.look_at = vec3(*t.get("look_at"), "camera.look_at");
  if (const toml::node* v = t.get("up")) c.up = vec3(*v, "camera.up");
  if (const toml::node* v = t.get("fov_deg")) c.fov_deg = number(*v, "camera.fov_deg");
  if (const toml::node* v = t.get("ortho_width")) c.ortho_width = number(*v, "camera.ortho_width");
  else if (c.projection == Projection::Orthographic)
    fail("camera.ortho_width", "missing: an orthographic camera needs the width of its view in parsecs");
  if (const toml::node* v = t.get("width")) c.width = small_integer(*v, "camera.width");
  if (const toml::node* v = t.get("height")) c.height = small_integer(*v, "camera.height");
  if (const toml::node* v = t.get("exposure")) c.exposure = number(*v, "camera.exposure");
  return c;
}

void Parser::parse_output(const toml::table& root, Scene& scene) const {
  const toml::node* n = root.get("output");
  if (n == nullptr) return;
  const toml::table& t = table_at(*n, "output");
  known_keys(t, "output", kOutputKeys);
  if (const toml::node* v = t.get("file")) scene.output = string(*v, "output.file");
  if (const toml::node* v = t.get("draw_stars")) scene.draw_stars = boolean(*v, "output.draw_stars");
  if (const toml::node* v = t.get("star_psf_pixels"))
    scene.star_psf_pixels = number(*v, "output.star_psf_pixels");
}

void Parser::parse_render(const toml::table& root, Scene& scene) const {
  const toml::node* n = root.get("render");
  if (n == nullptr) return;
  const toml::table& t = table_at(*n, "render");
  known_keys(t, "render", kRenderKeys);
  if (const toml::node* v = t.get("levels")) scene.pyramid_levels = small_integer(*v, "render.levels");
  // Levels without an explicit choice ask for the pyramid, as before the diffuse field existed.
  scene.multiple_scattering = scene.pyramid_levels > 0 ? MultipleScattering::Pyramid : MultipleScattering::Diffuse;
  if (const toml::node* v = t.get("multiple_scattering")) {
    const std::string mode = lower(string(*v, "render.multiple_scattering"));
    if (!parse_multiple_scattering(mode, scene.multiple_scattering))
      fail("render.multiple_scattering", "'" + mode + "' is not a mode (known: diffuse, pyramid, none)");
  }
  DiffuseSettings& d = scene.diffuse;
  // "auto" (any case) or a whole number >= 0; a negative number is refused
  // rather than taken for the auto marker.
  auto auto_or_count = [&](const char* name, int auto_value, const std::string& range, int& out) {
    const toml::node* v = t.get(name);
    if (!v) return;
    const std::string key = std::string("render.") + name;
    if (v->is_string() && lower(string(*v, key)) == "auto")
      out = auto_value;
    else if (v->is_string())
      fail(key, "must be \"auto\" or a whole number, got '" + string(*v, key) + "'");
    else if ((out = small_integer(*v, key)) < 0)
      fail(key, "is " + std::to_string(out) + "; must be " + range);
  };
  auto_or_count("diffuse_order", DiffuseSettings::kOrderAuto, "\"auto\" or in 0..4", d.order);
  auto_or_count("diffuse_zonal", DiffuseSettings::kZonalAuto,
                "\"auto\", 0 (none) or above render.diffuse_order, at most 32", d.zonal);
  if (const toml::node* v = t.get("diffuse_cells")) d.cells = small_integer(*v, "render.diffuse_cells");
  auto count = [&](const char* name, uint64_t& out) {
    const toml::node* v = t.get(name);
    if (!v) return;
    const std::string key = std::string("render.") + name;
    const double x = number(*v, key);
    if (!(x >= 0 && x <= 1.8e19) || x != std::floor(x)) fail(key, "must be a whole number >= 0, got " + number_text(x));
    out = static_cast<uint64_t>(x);
  };
  count("diffuse_photons", d.photons);
  count("diffuse_seed", d.seed);
  if (const toml::node* v = t.get("diffuse_taper")) {
    const std::string taper = lower(string(*v, "render.diffuse_taper"));
    if (!parse_diffuse_taper(taper, d.taper))
      fail("render.diffuse_taper", "'" + taper + "' is not a taper (known: auto, none, lanczos)");
  }
  if (const toml::node* v = t.get("samples_per_pixel")) {
    scene.samples_per_pixel = small_integer(*v, "render.samples_per_pixel");
    if (auto issue = scene_detail::samples_per_pixel_issue(scene.samples_per_pixel)) fail(issue->key, issue->reason);
  }
  if (const toml::node* v = t.get("star_pixels")) scene.star_pixels = boolean(*v, "render.star_pixels");
}

void Parser::load_grids(const DensityPlan& density, const std::optional<EmissionPlan>& emission,
                        Scene& scene) const {
  try {
    switch (density.kind) {
      case DensityKind::Hdf5: scene.density = load_density_hdf5(density.path, density.dataset); break;
      case DensityKind::Fits: scene.density = load_density_fits(density.path, density.voxel_size_pc); break;
      case DensityKind::Procedural: scene.density = procedural_nebula(density.procedural); break;
    }
  } catch (const Error& e) {
    fail(density.key, e.what());
  }
  scene.density_scale = density.scale;
  if (density.scale != 1) {
    for (float& v : scene.density.tau_v) v = static_cast<float>(v * density.scale);
    try {
      check_grid_values("tau_v after scaling", scene.density.shape, scene.density.tau_v);
    } catch (const Error& e) {
      fail("density.scale", e.what());
    }
  }
  if (emission) {
    // The density and the emission grids must fit together.
    const GridShape& s = scene.density.shape;
    try {
      check_grid_size("density and " + std::to_string(scene.bands.size()) + " emission grids",
                      uint64_t(s.nx), uint64_t(s.ny), uint64_t(s.nz),
                      sizeof(float) * (1 + scene.bands.size()));
      for (const std::string& band : scene.bands)
        scene.emission.push_back(load_emission_hdf5(emission->path, emission->prefix + band, s));
    } catch (const Error& e) {
      fail("emission.file", e.what());
    }
    scene.emission_scale = emission->scale;
    if (emission->scale != 1)
      for (std::vector<float>& plane : scene.emission)
        for (float& v : plane) {
          v = static_cast<float>(v * emission->scale);
          if (!std::isfinite(v)) fail("emission.scale", "makes an emission value overflow a float (inf)");
        }
  }
}

// The spectral emission components' weight grids (files named in
// [[spectral.emission]]), their scale applied; checked before any is used.
void Parser::load_spectral_emission(Scene& scene) const {
  SpectralSpec& p = *scene.spectral;
  p.emission_grids.assign(p.emission.size(), {});
  const GridShape& s = scene.density.shape;
  for (size_t i = 0; i < p.emission.size(); ++i) {
    const SpectralEmissionSpec& c = p.emission[i];
    const std::string key = "spectral.emission." + std::to_string(i);
    if (!(std::isfinite(c.scale) && c.scale >= 0)) fail(key + ".scale", "is " + number_text(c.scale) + "; must be >= 0 and finite");
    if (c.file.empty()) continue;
    try {
      check_grid_size("an emission weight grid", uint64_t(s.nx), uint64_t(s.ny), uint64_t(s.nz), 2 * sizeof(float));
      p.emission_grids[i] = load_emission_hdf5(c.file, c.dataset, s);
    } catch (const Error& e) {
      fail(key + ".file", e.what());
    }
    for (float& v : p.emission_grids[i]) {
      v = static_cast<float>(v * c.scale);
      if (!std::isfinite(v)) fail(key + ".scale", "makes a weight overflow a float (inf)");
    }
  }
}

Scene Parser::build(toml::table& root, const Scene* reuse_grids) {
  known_keys(root, "", kTopKeys);
  Scene scene;
  scene.path = name_;
  scene.filters = parse_filters(root);
  scene.bands = parse_bands(root, scene.filters);
  scene.spectral = parse_spectral(root);
  const bool axial = root.get("axial") != nullptr;
  if (axial && root.get("density") != nullptr)
    fail_tables("axial", "conflicts with [density]: a scene is either a 3D grid or an axial map", {"axial", "density"});
  if (axial && root.get("emission") != nullptr)
    fail("emission", "applies to [density] grids; an axial map carries its own emission (axial.emission_prefix, "
                     "axial.emission_channels)");
  if (scene.spectral && root.get("emission") != nullptr)
    fail("emission", "holds one grid per band; the spectral renderer takes emission as lines and continua "
                     "([[spectral.emission]], docs/scene.md)");
  DensityPlan density;
  if (axial) {
    density.kind = DensityKind::Hdf5;  // stars need an explicit position
    scene.axial = parse_axial(root, scene.bands);
  } else {
    density = parse_density(root);
  }
  const std::optional<EmissionPlan> emission = axial ? std::nullopt : parse_emission(root);
  scene.dust = parse_dust(root, scene.bands);
  scene.stars = parse_stars(root, density);
  const bool spectral_emission = scene.spectral && !scene.spectral->emission.empty();
  if (scene.stars.empty() && !emission && !axial && !spectral_emission)
    fail("stars", "missing: a scene needs at least one [[stars]] entry (or an [emission] grid)");
  if (axial) {
    // Stars on the axis keep the illumination axisymmetric (DESIGN.md section 3).
    const AxialSpec& a = *scene.axial;
    for (size_t i = 0; i < scene.stars.size(); ++i) {
      const Vec3 q = scene.stars[i].position - a.origin;
      const Vec3 off = q - dot(q, a.axis) * a.axis;
      if (!(length(off) <= 1e-6 * (a.length_pc + length(q))))
        fail("stars." + std::to_string(i) + ".position",
             "is " + number_text(length(off)) + " pc from the axial map's axis; stars of an axial scene must lie on "
             "its axis (axial.origin + s * axial.axis)");
    }
  }
  scene.camera = parse_camera(root);
  if (const toml::node* a = root.get("animation"))
    scene.camera_path = scene_detail::parse_camera_path(
        *a, scene.camera, [this](const std::string& key, const std::string& reason) { fail(key, reason); });
  if (const toml::node* d = root.get("display"))
    scene.display = scene_detail::parse_display(*d, [this](const std::string& key, const std::string& reason) { fail(key, reason); });
  parse_output(root, scene);
  parse_render(root, scene);
  if (const auto issue = scene_detail::settings_issue(scene)) fail(issue->key, issue->reason);
  // Every file the scene reads, so that no output is written over one of them.
  if (!density.path.empty()) scene.inputs.push_back({density.key, density.path});
  if (emission) scene.inputs.push_back({"emission.file", emission->path});
  if (axial && !scene.axial->path.empty()) scene.inputs.push_back({"axial." + scene.axial->source, scene.axial->path});
  for (const SceneFilter& f : scene.filters) scene.inputs.push_back({"filters." + f.name, f.path});
  if (scene.spectral)
    for (size_t i = 0; i < scene.spectral->emission.size(); ++i)
      if (!scene.spectral->emission[i].file.empty())
        scene.inputs.push_back({"spectral.emission." + std::to_string(i) + ".file", scene.spectral->emission[i].file});
  for (size_t b = 0; b < scene.dust.table_files.size(); ++b)
    if (!scene.dust.table_files[b].empty())
      scene.inputs.push_back({"dust.tables." + scene.bands[b], scene.dust.table_files[b]});
  // What the grids are made of: the [density] and [emission] tables as
  // printed, with an [emission] table the bands (its grids follow them), and
  // the scene's folder.
  if (!axial) {
    std::ostringstream source;
    source << "base=" << base_.string();
    if (const toml::table* d = root["density"].as_table()) source << "\n[density]\n" << toml::toml_formatter(*d);
    if (const toml::table* e = root["emission"].as_table()) {
      source << "\nbands=";
      for (const std::string& b : scene.bands) source << b << ",";
      source << "\n[emission]\n" << toml::toml_formatter(*e);
    }
    scene.grid_source = source.str();
  }
  if (!axial && reuse_grids && !reuse_grids->grid_source.empty() && reuse_grids->grid_source == scene.grid_source) {
    scene.density = reuse_grids->density;
    scene.density.device_tau_v.share(reuse_grids->density.device_tau_v);  // the same grid: its GPU copy too
    scene.emission = reuse_grids->emission;
  } else if (!axial) {
    load_grids(density, emission, scene);  // the expensive part, last
  }
  if (scene.spectral && !axial) load_spectral_emission(scene);
  if (const auto issue = scene_detail::grids_issue(scene)) fail(issue->key, issue->reason);
  return scene;
}

Scene parse_scene(const std::string& text, const std::string& name, const fs::path& base,
                  const std::vector<std::string>& overrides, const Scene* reuse_grids) {
  toml::table root;
  try {
    root = toml::parse(std::string_view(text), std::string_view(name));
  } catch (const toml::parse_error& e) {
    const auto& where = e.source().begin;
    throw Error(one_line(name + ":" + std::to_string(where.line) + ":" +
                         std::to_string(where.column) + ": TOML syntax: " +
                         std::string(e.description())));
  }
  Parser parser(name, base);
  parser.note_file_tables(root);
  for (const std::string& o : overrides) parser.apply_override(root, o);
  std::ostringstream resolved;
  resolved << toml::toml_formatter(root);
  Scene scene = parser.build(root, reuse_grids);
  scene.resolved_toml = resolved.str();
  return scene;
}

}  // namespace

Scene load_scene_text(const std::string& text, const std::string& name, const std::string& base_dir,
                      const std::vector<std::string>& overrides, const Scene* reuse_grids) {
  return parse_scene(text, name, fs::path(base_dir), overrides, reuse_grids);
}

Scene load_scene(const std::string& path, const std::vector<std::string>& overrides) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const int err = errno;
    throw Error(path + ": cannot read the scene file (" + std::strerror(err ? err : ENOENT) + ")");
  }
  std::error_code ec;
  if (fs::is_directory(path, ec)) throw Error(path + ": cannot read the scene file (a directory)");
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(path + ": cannot read the scene file");
  Scene scene = parse_scene(text.str(), path, fs::path(path).parent_path(), overrides, nullptr);
  scene.inputs.insert(scene.inputs.begin(), SceneInput{"scene", path});
  return scene;
}

// The recipe's parts (bubble, shell, fall-off, far side, noise) tuned to show
// structure (issue 13): an off-centre star, finer and stronger noise, filaments,
// the far side's boundary behind the star and warped, faded cube faces.
ProceduralParams demo_procedural_params() {
  ProceduralParams p;
  p.star = Vec3{0.40f, 0.52f, 0.55f};
  p.wind_direction = Vec3{0.3f, -1.0f, 0.4f};
  p.bubble_offset = 0.05;
  p.bubble_radius = 0.15;
  p.bubble_tau = 0.3;
  p.shell_thickness = 0.05;
  p.shell_tau = 14.0;
  p.cloud_tau = 8.0;
  p.scale_length = 0.18;
  p.far_multiplier = 5.0;
  p.far_transition = 0.08;
  p.far_offset = 0.12;
  p.far_warp = 0.15;
  p.noise_amplitude = 3.2;
  p.noise_frequency = 5.0;
  p.noise_octaves = 6;
  p.noise_gain = 0.65;
  p.filament_amplitude = 5.0;
  p.filament_frequency = 3.0;
  p.filament_octaves = 3;
  p.filament_sharpness = 10.0;
  p.edge_fade = 0.45;
  return p;
}

Scene demo_scene() {
  Scene scene;
  scene.path = "demo";
  const ProceduralParams params = demo_procedural_params();
  scene.density = procedural_nebula(params);
  scene.dust.albedo.assign(scene.bands.size(), 0.6);
  scene.dust.g.assign(scene.bands.size(), 0.6);
  scene.dust.R_V = 5.0;
  scene.dust.law = ExtinctionLaw::CCM89;
  scene.dust.table_files.assign(scene.bands.size(), "");
  SceneStar star;
  star.name = "O5V star";
  star.position = procedural_star_position(params);
  star.luminosity_lsun = 2e5;
  star.spectral_class = "O5V";
  star.temperature_K = effective_temperature_K("O5V");
  scene.stars.push_back(star);
  scene.camera.projection = Projection::Perspective;
  scene.camera.position = Vec3{2.9f, -1.9f, 1.5f};
  scene.camera.look_at = Vec3{1.1f, 1.0f, 1.05f};  // beside the star: it sits left of centre
  scene.camera.up = Vec3{0, 0, 1};
  scene.camera.fov_deg = 50;
  scene.camera.width = scene.camera.height = 512;
  scene.camera.exposure = 0.02;  // recorded; the PNG's auto exposure picks its own
  scene.display.stretch = Stretch::Asinh;
  scene.display.auto_exposure = true;
  scene.display.percentile = 99.9;
  scene.display.softening = 0.01;
  // A fly-around that ends close to the star (`nebula animate --demo`).
  CameraPath path;
  const Vec3 stops[] = {{2.9f, -1.9f, 1.5f}, {-0.9f, -2.4f, 1.3f}, {-1.6f, 0.6f, 1.9f}, {0.2f, -0.6f, 1.2f}};
  const double times[] = {0, 4, 8, 10};
  for (int i = 0; i < 4; ++i) {
    CameraKeyframe k;
    k.time = times[i];
    k.position = stops[i];
    k.look_at = scene.camera.look_at;
    k.up = scene.camera.up;
    k.fov_deg = scene.camera.fov_deg;
    path.keys.push_back(k);
  }
  scene.camera_path = path;
  scene.output = "demo.exr";
  scene.draw_stars = false;
  scene.star_psf_pixels = 1.5;
  validate_scene(scene);
  return scene;
}

namespace {

toml::table parsed_scene_text(const std::string& text) {
  try {
    return toml::parse(std::string_view(text), std::string_view("scene"));
  } catch (const toml::parse_error& e) {
    throw Error(one_line(std::string("scene text: TOML syntax: ") + std::string(e.description())));
  }
}

}  // namespace

std::string scene_text_without(const std::string& text, const std::vector<std::string>& keys) {
  toml::table root = parsed_scene_text(text);
  for (const std::string& key : keys) {
    toml::table* table = &root;
    std::string rest = key;
    for (size_t dot = rest.find('.'); table != nullptr && dot != std::string::npos; dot = rest.find('.')) {
      table = (*table)[rest.substr(0, dot)].as_table();
      rest = rest.substr(dot + 1);
    }
    if (table != nullptr) table->erase(rest);
  }
  std::ostringstream out;
  out << toml::toml_formatter(root);
  return out.str();
}

std::string scene_text_with_axial_file(const std::string& text, const std::string& file,
                                       const std::string& emission_prefix) {
  toml::table root = parsed_scene_text(text);
  toml::table* axial = root["axial"].as_table();
  if (axial == nullptr) throw Error("scene text: no [axial] table to point at " + file);
  for (const char* key : {"synthetic", "nx", "nr", "file", "image", "dataset", "emission_prefix", "tau_channel",
                          "emission_channels"})
    axial->erase(key);
  axial->insert_or_assign("file", file);
  axial->insert_or_assign("dataset", "tau_v");
  if (!emission_prefix.empty()) axial->insert_or_assign("emission_prefix", emission_prefix);
  axial->insert_or_assign("tau_scale", 1.0);
  axial->insert_or_assign("emission_scale", 1.0);
  std::ostringstream out;
  out << toml::toml_formatter(root);
  return out.str();
}

}  // namespace nebula
