// CUDA launch of the spectral marcher: the model's tables, the grid and the
// baked depths uploaded, then one thread per pixel runs the shared
// march_spectral (spectral/spectral_march.h) and writes its accumulators.
#include <cuda_runtime.h>

#include <memory>
#include <string>
#include <vector>

#include "core/cuda_check.h"
#include "core/cuda_side_stream.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "illumination/star_pixels_cuda.h"
#include "spectral/spectral_renderer.h"

namespace nebula::spectral {
namespace {

thread_local SideStream near_rays;  // the launch of the rays near a star (spectral_kernel)
thread_local SideStream star_pixel_rays;  // the star pixels' rays, on their own beside both launches

// Blocks of 256 rays per multiprocessor the main launch (kNear false) is held
// to: the projection's at 3 (at most 80 registers, against 113 unbounded). One
// H200 run, each bound a build's variant (docs/performance.md): the Fig. 12
// scene's projection 0.94 -> 0.84 ms at 512^2, the noise cube's 0.47 -> 0.46 ms
// (its frame waits on the near rays); the other methods slower held so (on the
// noise cube the light basis 0.58 -> 0.68 ms, voxel light 1.48 -> 1.72 ms,
// pre-integration 0.46 -> 0.49 ms, the double integral's 20 samples 2.16 ->
// 2.59 ms), so they and the near rays' launch keep the compiler's choice.
constexpr int main_min_blocks(SpectralMethod m) { return m == SpectralMethod::Projection ? 3 : 1; }

// kNear: the rays passes_near_a_star picks (the phase's mean over their
// chords' angles), else the others; a launch of each marches every pixel once.
// The split keeps that mean out of the main kernel's registers (the near
// rays' launch runs beside it on a SideStream); the image is the CPU loop's.
template <SpectralMethod kMethod, class Acc, bool kNear>
__global__ void __launch_bounds__(256, kNear ? 1 : main_min_blocks(kMethod)) spectral_kernel(SpectralSceneView scene, Camera camera, float* pixels) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x;
  const int y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= camera.width || y >= camera.height) return;
  Vec3 origin, dir;
  if (!camera.ray(x, y, origin, dir)) return;
  if (passes_near_a_star(scene, origin, dir) != kNear) return;
  Acc acc;
  float em[kMaxEmissionPlanes];  // local memory, touched only with emission
  march_spectral<kMethod, kNear>(scene, origin, dir, acc, em);
  const size_t stride = size_t(camera.width) * camera.height;
  store_accumulators(scene, acc, pixels + size_t(y) * camera.width + x, stride);
  store_emission(scene, em, pixels + size_t(y) * camera.width + x, stride);
}

// One thread per ray of the pixels at each star's image (illumination/star_pixels.h),
// each standing for its sub-cell, into sub (plane k of ray i at sub[k * rays + i]).
template <SpectralMethod kMethod, class Acc>
__global__ void spectral_star_pixel_kernel(SpectralSceneView scene, Camera camera, const StarPixel* list, int n,
                                           int rays, int n_planes, float* sub) {
  const int i = blockIdx.x * blockDim.x + threadIdx.x;
  if (i >= rays) return;
  const RayFootprint pixel = scene.footprint;
  march_star_pixel_ray(camera, list, n, rays, i, n_planes, sub,
                       [&](Vec3 origin, Vec3 dir, float narrowing, float* out, size_t stride) {
    scene.footprint = sub_pixel_footprint(pixel, narrowing);
    Acc acc;
    float em[kMaxEmissionPlanes];
    march_spectral<kMethod, true>(scene, origin, dir, acc, em);
    store_accumulators(scene, acc, out, stride);
    store_emission(scene, em, out, stride);
    return 0;
  });
}

// VoxelLight's per-view pre-pass (spectral_march.h, voxel_light): each
// voxel's F N outputs (and their gradients) in slices of kVoxelLightSlice, a
// thread each, a voxel's slices side by side; each thread keeps its slice's
// sums in registers and repeats the pairs' geometry. One voxel per thread with
// every sum (slices of 16) took 128 registers at 25% occupancy and waited on
// its reads; in slices of 16 / 8 / 4 / 2, H200, noise cube 96^3 at 512^2 with
// the table at 3 attenuations, voxel light N = 4, six stars and one: 2.06 /
// 1.96 / 1.73-1.79 / 1.93 ms and 1.51 / 1.33 / 1.06-1.09 / 1.08 ms
// (docs/performance.md, "The voxel-light pre-pass in slices").
constexpr int kVoxelLightBlock = 128;
constexpr int kVoxelLightSlice = 4;
__global__ void __launch_bounds__(kVoxelLightBlock, 8)
    voxel_light_kernel(SpectralSceneView scene, Camera camera, float* light, unsigned* near, int slices) {
  const GridShape& g = scene.density.shape;
  const size_t t = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  const size_t i = t / unsigned(slices);
  if (i >= g.count()) return;
  const int x = int(i % g.nx), y = int((i / g.nx) % g.ny), z = int(i / (size_t(g.nx) * g.ny));
  voxel_light<1, kVoxelLightSlice>(scene, camera, x, y, z, light, near, int(t % unsigned(slices)));
}

// Light between voxels: each voxel's terms per star and its eye-side depth
// (diffuse_voxel_terms, diffuse_eye_depth), one voxel per thread, from the
// per-view arrays light[k * n + m] (star k, node m) and peak[m] where they lie
// on the device; power[k * n + m] the star's pass' power at the node.
__global__ void diffuse_terms_kernel(SpectralSceneView scene, const float* const* light, const float* const* peak,
                                     const float* power, int stars, float* terms, float* eye_tau) {
  const size_t v = size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (v >= scene.density.shape.count()) return;
  const int n = scene.n_nodes;
  float H[kMaxTableNodes], P[kMaxTableNodes], pk[kMaxTableNodes];
  for (int k = 0; k < stars; ++k) {
    for (int m = 0; m < n; ++m) {
      H[m] = light[k * n + m][v];
      P[m] = power[k * n + m];
    }
    diffuse_voxel_terms(scene, H, P, terms + (v * stars + k) * size_t(n + 1));
  }
  for (int m = 0; m < n; ++m) pk[m] = peak[m][v];
  eye_tau[v] = diffuse_eye_depth(scene, pk, scene.density.tau_v[v]);
}

// The smallest of the bounds in `sizes` that holds n, or 0 (run-time extents).
template <int... kSizes>
constexpr int bucket(int n) {
  int out = 0;
  ((out = out == 0 && n <= kSizes ? kSizes : out), ...);
  return out;
}

template <int N>
using Int = std::integral_constant<int, N>;
constexpr int kBasisInColumns = 0;  // the basis size is the column count (Projection, LightBasis; Double: unused)

// Launches kernel<kMethod, Acc>() with the accumulators' compile-time bounds
// (RayAccumulators): per method the smallest bucket that holds the run's
// rows, columns and basis, or run-time extents beyond them.
template <SpectralMethod kMethod, class Launch>
void with_accumulators(const SpectralSceneView& v, Launch&& launch) {
  const int rows = accumulator_rows(v), cols = accumulator_cols(v);
  auto by_cols = [&](auto rows_bound, auto basis_bound) {
    constexpr int R = decltype(rows_bound)::value, B = decltype(basis_bound)::value;
    switch (bucket<4, 8>(cols)) {
      case 4: launch(RayAccumulators<R, 4, B == kBasisInColumns ? 4 : B>()); break;
      case 8: launch(RayAccumulators<R, 8, B == kBasisInColumns ? 8 : B>()); break;
      default: launch(DynamicAccumulators()); break;
    }
  };
  if constexpr (kMethod == SpectralMethod::Projection) {  // a row per star, basis in the columns
    switch (bucket<1, 2, 4, 8>(rows)) {
      case 1: by_cols(Int<1>(), Int<kBasisInColumns>()); break;
      case 2: by_cols(Int<2>(), Int<kBasisInColumns>()); break;
      case 4: by_cols(Int<4>(), Int<kBasisInColumns>()); break;
      case 8: by_cols(Int<8>(), Int<kBasisInColumns>()); break;
      default: launch(DynamicAccumulators()); break;
    }
  } else if constexpr (kMethod == SpectralMethod::VoxelLight) {  // filters in the columns, the basis apart
    switch (bucket<4, 8>(v.n_basis)) {
      case 4: by_cols(Int<1>(), Int<4>()); break;
      case 8: by_cols(Int<1>(), Int<8>()); break;
      default: launch(DynamicAccumulators()); break;
    }
  } else {  // Double, Analytic (filters), LightBasis (basis) in the columns
    by_cols(Int<1>(), Int<kBasisInColumns>());
  }
}

template <class T>
const T* upload(std::vector<std::unique_ptr<DeviceArray<T>>>& keep, const std::vector<T>& host) {
  if (host.empty()) return nullptr;
  keep.push_back(std::make_unique<DeviceArray<T>>(host));
  return keep.back()->get();
}

}  // namespace

Image render_spectral_cuda(const SpectralRenderInputs& in, double* seconds) {
  const SpectralModel& m = *in.model;
  std::vector<std::unique_ptr<DeviceArray<float>>> floats;
  std::vector<std::unique_ptr<DeviceArray<double>>> doubles;
  std::vector<std::unique_ptr<DeviceArray<int>>> ints;
  std::vector<std::unique_ptr<DeviceArray<SpectralStarView>>> star_arrays;
  SpectralSceneView view = view_of(m);
  view.density = {in.density->shape, upload(floats, in.density->tau_v)};
  std::vector<SpectralStarView> stars;
  for (size_t k = 0; k < in.lights.size(); ++k)
    stars.push_back({in.lights[k].position, float(in.lights[k].luminosity_lsun), upload(floats, *in.lights[k].depth_v),
                     m.temperature_u.empty() ? 0.0f : m.temperature_u[k]});
  star_arrays.push_back(std::make_unique<DeviceArray<SpectralStarView>>(stars));
  view.stars = stars.empty() ? nullptr : star_arrays.back()->get();
  view.n_stars = int(stars.size());
  view.albedo = in.albedo;
  view.g = in.g;
  view.footprint = in.camera.footprint();
  std::vector<const float*> node_P, node_C;
  for (const ScatteringTable* t : in.node_tables) {
    node_P.push_back(upload(floats, t->P));
    node_C.push_back(upload(floats, cumulative_rows(*t)));
  }
  set_table(view, in, in.table ? upload(floats, in.table->P) : nullptr,
            in.table ? upload(floats, cumulative_rows(*in.table)) : nullptr, node_P, node_C);
  const NodeTable nodes = node_table(in, view);
  if (!nodes.values.empty()) use_node_table(view, nodes, upload(floats, nodes.values));
  // Light between voxels: the per-view arrays where they lie (a CUDA pass leaves them on the
  // device; host arrays are uploaded here), the terms made by a kernel timed with the march.
  const size_t cells = in.density->shape.count();
  std::vector<const float*> light_ptrs, peak_ptrs;
  std::vector<float> powers;
  DeviceArray<float> terms(in.diffuse ? cells * in.lights.size() * size_t(view.n_nodes + 1) : 0);
  DeviceArray<float> eye_tau(in.diffuse ? cells : 0);
  std::vector<std::shared_ptr<const void>> mirrored;  // the device copies' owners, alive for the kernel
  if (const SpectralDiffuseLight* d = in.diffuse) {
    const auto device_of = [&](const DeviceMirror& mirror) {  // check() made sure it holds the array
      const DeviceMirror::Copy c = mirror.current();
      mirrored.push_back(c.owner);
      return static_cast<const float*>(c.device);
    };
    for (size_t k = 0; k < in.lights.size(); ++k)
      for (int m = 0; m < view.n_nodes; ++m) {
        light_ptrs.push_back(d->on_device() ? device_of(d->device_light[k][size_t(m)])
                                            : upload(floats, d->light[k][size_t(m)]));
        powers.push_back(float(d->node_power[k][size_t(m)]));
      }
    for (int m = 0; m < view.n_nodes; ++m)
      peak_ptrs.push_back(d->on_device() ? device_of(d->device_peak[size_t(m)]) : upload(floats, d->peak[size_t(m)]));
    view.diffuse = terms.get();
    view.eye_tau = eye_tau.get();
  }
  DeviceArray<const float*> light_table(light_ptrs), peak_table(peak_ptrs);
  const DeviceArray<float> power(powers);
  view.kappa = upload(floats, m.kappa);
  view.lambda_albedo = upload(floats, m.lambda_albedo);  // varying albedo and g: the double integral's
  view.lambda_g = upload(floats, m.lambda_g);
  view.q = upload(floats, m.q);
  view.coeff = upload(floats, m.coeff);
  view.breaks = upload(doubles, m.breaks);
  view.jumps = upload(doubles, m.jumps);
  view.break_range = upload(ints, m.break_range);
  view.star_coeff = upload(floats, m.star_coeff);
  view.emission_q = upload(floats, m.emission_q);
  view.emission_jumps = upload(doubles, m.emission_jumps);
  view.emission_coeff = m.emission_coeff.empty() ? view.coeff : upload(floats, m.emission_coeff);
  std::vector<const float*> grids;
  for (const SpectralEmissionWeight& e : in.emission) grids.push_back(e.grid ? upload(floats, *e.grid) : nullptr);
  set_emission(view, in, grids);
  const bool voxel = m.settings.method == SpectralMethod::VoxelLight;
  DeviceArray<float> light(voxel ? cells * 4 * size_t(m.n_acc) * m.basis.size() : 0);
  DeviceArray<unsigned> near(voxel ? cells : 0);
  if (voxel) {
    view.near_distance = float(m.settings.near_voxels) * in.density->shape.voxel;
    view.voxel_light = light.get();
    view.near_stars = near.get();
  }
  std::vector<std::string> names;
  for (int k = 0; k < m.planes(); ++k) names.push_back("acc" + std::to_string(k));
  Image image(in.camera.width, in.camera.height, names);
  DeviceArray<float> pixels(image.pixels.size());
  const dim3 block(16, 16), grid((in.camera.width + 15) / 16, (in.camera.height + 15) / 16);
  std::vector<Vec3> positions;
  if (in.star_pixels)
    for (const SpectralLight& l : in.lights) positions.push_back(l.position);
  int rays = 0;
  const std::vector<StarPixel> list = star_pixels(in.camera, positions, &rays);
  const DeviceArray<StarPixel> device_list(list);
  DeviceArray<float> sub(size_t(rays) * size_t(m.planes()));
  CudaEventTimer timer;
  const unsigned pre_blocks = unsigned((cells + 255) / 256);
  if (in.diffuse) {
    diffuse_terms_kernel<<<pre_blocks, 256>>>(view, light_table.get(), peak_table.get(), power.get(),
                                              int(in.lights.size()), terms.get(), eye_tau.get());
  }
  if (voxel) {  // the pre-pass, timed with the march
    const int FN = m.n_acc * int(m.basis.size()), slices = (FN + kVoxelLightSlice - 1) / kVoxelLightSlice;
    const unsigned blocks = unsigned((cells * slices + kVoxelLightBlock - 1) / kVoxelLightBlock);
    voxel_light_kernel<<<blocks, kVoxelLightBlock>>>(view, in.camera, light.get(), near.get(), slices);
  }
  dispatch_method(m.settings.method, [&](auto method) {
    with_accumulators<method()>(view, [&](auto acc) {
      if (view.n_stars > 0) {
        // The star pixels' rays first, on a stream of their own: the frame's longest rays,
        // so they end beside the main launch rather than after the near rays.
        if (!list.empty()) {
          star_pixel_rays.start();
          spectral_star_pixel_kernel<method(), decltype(acc)>
              <<<unsigned((rays + 127) / 128), 128, 0, star_pixel_rays.stream>>>(
                  view, in.camera, device_list.get(), int(list.size()), rays, m.planes(), sub.get());
        }
        near_rays.start();
        spectral_kernel<method(), decltype(acc), true>
            <<<grid, block, 0, near_rays.stream>>>(view, in.camera, pixels.get());
        spectral_kernel<method(), decltype(acc), false><<<grid, block>>>(view, in.camera, pixels.get());
        near_rays.join();
        if (!list.empty()) star_pixel_rays.join();
        if (!list.empty())  // after every launch: the star pixels replace their single rays
          store_star_pixels_cuda(device_list.get(), int(list.size()), sub.get(), rays, m.planes(), 1.0f, pixels.get(),
                                 in.camera.width, in.camera.height);
      } else {
        spectral_kernel<method(), decltype(acc), false><<<grid, block>>>(view, in.camera, pixels.get());
      }
    });
  });
  NEBULA_CUDA_CHECK(cudaGetLastError());
  const double s = timer.seconds();
  if (seconds) *seconds = s;
  pixels.download(image.pixels.data());
  return image;
}

}  // namespace nebula::spectral
