#include "pipeline/axial_map_source.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "core/error.h"
#include "imageio/image_output.h"
#include "scene/density_sources.h"

namespace nebula {
namespace {

// An image map: column ix is x along the axis, the bottom row is the axis
// (r = 0) and row 0 the outermost texels (a picture of the upper half-plane).
void read_image_map(const Scene& scene, AxialMap& m) {
  const AxialSpec& a = *scene.axial;
  const std::string key = scene.path + ": axial.image: ";
  // The project's float files through read_image (any EXR included), every
  // other format OpenImageIO knows through read_any_image.
  std::string ext = std::filesystem::path(a.path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool ours = ext == ".h5" || ext == ".fits" || ext == ".fit" || ext == ".exr";
  Image image;
  try {
    image = ours ? read_image(a.path) : read_any_image(a.path);
  } catch (const Error& e) {
    throw Error(key + e.what());
  }
  auto channel = [&](const std::string& name, const std::string& option) -> int {
    for (size_t c = 0; c < image.bands.size(); ++c)
      if (image.bands[c] == name) return int(c);
    std::string list;
    for (const std::string& b : image.bands) list += (list.empty() ? "" : ", ") + b;
    throw Error(scene.path + ": " + option + ": '" + name + "' is not a channel of " + a.path + " (it has: " + list + ")");
  };
  m.nx = image.width;
  m.nr = image.height;
  m.tau_v.assign(m.count(), 0.0f);
  auto copy = [&](int c, std::vector<float>& out) {
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) out[m.index(x, image.height - 1 - y)] = image.at(c, x, y);
  };
  copy(channel(a.tau_channel, "axial.tau_channel"), m.tau_v);
  bool any = false;
  for (const std::string& c : a.emission_channels) any = any || !c.empty();
  if (any) {
    m.emission.assign(scene.bands.size(), std::vector<float>(m.count(), 0.0f));
    for (size_t b = 0; b < scene.bands.size(); ++b)
      if (!a.emission_channels[b].empty())
        copy(channel(a.emission_channels[b], "axial.emission_channels." + scene.bands[b]), m.emission[b]);
  }
}

// The scene's step check and the map's placement: texel, origin, axis.
void place(const Scene& scene, AxialMap& m) {
  const AxialSpec& a = *scene.axial;
  // A step longer than the map crosses it in one sample: the march would see
  // (almost) nothing of it, a wrong image rather than a coarse one.
  const int map_texels = std::max(m.nx, m.nr);
  if (!(a.step_texels <= map_texels))
    throw ParameterError("axial.step_texels", "is " + to_text(a.step_texels) + "; must be at most " +
                                                  std::to_string(map_texels) + ", the map's larger size in texels");
  m.texel = static_cast<float>(a.length_pc / m.nx);
  m.origin = a.origin;
  m.axis = a.axis;
}

}  // namespace

AxialMap place_axial_map(const Scene& scene, AxialMap m) {
  if (!m.emission.empty() && m.emission.size() != scene.bands.size())
    throw Error(scene.path + ": axial: the map in memory has " + std::to_string(m.emission.size()) +
                " emission planes for the scene's " + std::to_string(scene.bands.size()) + " bands");
  place(scene, m);
  check_axial_map(m, scene.path + ": axial");
  m.update_skip_structures();
  return m;
}

AxialMap build_axial_map(const Scene& scene) {
  const AxialSpec& a = *scene.axial;
  AxialMap m;
  if (a.source == "synthetic") {
    // tau_v and one emission plane per band, refused before allocating when
    // they would exceed half the memory (as density grids are).
    try {
      check_grid_size("synthetic map " + a.synthetic, uint64_t(a.nx), uint64_t(a.nr), 1,
                      sizeof(float) * (1 + scene.bands.size()));
    } catch (const Error& e) {
      throw Error(scene.path + ": axial.nx: " + e.what());
    }
    m = synthetic_axial_map(a.synthetic, a.nx, a.nr, 1.0f, int(scene.bands.size()));
  } else if (a.source == "file") {
    try {
      m.tau_v = load_axial_plane_hdf5(a.path, a.dataset, m.nx, m.nr);
      if (!a.emission_prefix.empty())
        for (const std::string& band : scene.bands) {
          int nx = 0, nr = 0;
          m.emission.push_back(load_axial_plane_hdf5(a.path, a.emission_prefix + band, nx, nr, "emission"));
          if (nx != m.nx || nr != m.nr)
            throw Error(a.path + ": dataset '" + a.emission_prefix + band + "' is " + std::to_string(nr) + " x " +
                        std::to_string(nx) + ", the map " + std::to_string(m.nr) + " x " + std::to_string(m.nx));
        }
    } catch (const Error& e) {
      throw Error(scene.path + ": axial.file: " + e.what());
    }
  } else {
    read_image_map(scene, m);
  }
  place(scene, m);
  for (float& v : m.tau_v) v = static_cast<float>(v * a.tau_scale);
  if (a.emission_scale == 0) m.emission.clear();
  for (auto& plane : m.emission)
    for (float& v : plane) v = static_cast<float>(v * a.emission_scale);
  check_axial_map(m, scene.path + ": axial");
  m.update_skip_structures();
  return m;
}

}  // namespace nebula
