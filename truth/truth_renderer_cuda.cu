// CUDA launch of the path tracer: the path scene is assembled with a device
// placement (the density, majorant grid, emission and stars uploaded), then
// the shared trace_pixel_samples runs per (pixel, share of its samples) and
// a second kernel adds each pixel's shares in order and takes its moments.
// One thread per pixel leaves most of a GPU idle on the small images of the
// validation studies (64 x 64: 4096 threads), where each thread traces
// thousands of long paths in turn; sharing the samples fills it.
#include <cuda_runtime.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/device_placement.h"
#include "truth/truth_renderer.h"

namespace nebula {
namespace {

// Thread i traces share i / pixels of pixel i % pixels: neighbouring threads
// trace neighbouring pixels (coherent paths). Sums laid out [share][band][pixel];
// with one share the thread writes the pixel's moments itself (no sums kept).
__global__ void truth_samples_kernel(PathScene scene, Camera camera, float exposure, int spp, int shares,
                                     double* sums, double* sums2, float* image, float* variance,
                                     unsigned long long* counters) {
  const long long pixels = static_cast<long long>(camera.width) * camera.height;
  const long long i = static_cast<long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= pixels * shares) return;
  const int share = static_cast<int>(i / pixels);
  const long long at = i % pixels;
  const int x = static_cast<int>(at % camera.width), y = static_cast<int>(at / camera.width);
  const int k0 = static_cast<int>(static_cast<long long>(spp) * share / shares);
  const int k1 = static_cast<int>(static_cast<long long>(spp) * (share + 1) / shares);
  PathCounters c;
  PixelSums p;
  trace_pixel_samples(scene, camera, x, y, k0, k1, p, c);
  if (shares == 1) {
    float mean[kMaxBands], var[kMaxBands];
    pixel_moments(p, scene.n_bands, spp, exposure, mean, var);
    for (int b = 0; b < scene.n_bands; ++b) {
      image[b * pixels + at] = mean[b];
      variance[b * pixels + at] = var[b];
    }
  }
  for (int b = 0; b < scene.n_bands && shares > 1; ++b) {
    const long long to = (static_cast<long long>(share) * scene.n_bands + b) * pixels + at;
    sums[to] = p.sum[b];
    sums2[to] = p.sum2[b];
  }
  atomicAdd(&counters[0], static_cast<unsigned long long>(c.vertices));
  atomicAdd(&counters[1], static_cast<unsigned long long>(c.tentative));
  if (c.capped) atomicAdd(&counters[2], static_cast<unsigned long long>(c.capped));
  Vec3 o, d;
  if (share == 0 && camera.ray(x, y, o, d)) atomicAdd(&counters[3], 1ull);
}

__global__ void truth_moments_kernel(int n_bands, long long pixels, int spp, int shares, float exposure,
                                     const double* sums, const double* sums2, float* image, float* variance) {
  const long long at = static_cast<long long>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (at >= pixels) return;
  PixelSums p;
  for (int b = 0; b < kMaxBands; ++b) p.sum[b] = p.sum2[b] = 0.0;
  for (int share = 0; share < shares; ++share)
    for (int b = 0; b < n_bands; ++b) {
      const long long from = (static_cast<long long>(share) * n_bands + b) * pixels + at;
      p.sum[b] += sums[from];
      p.sum2[b] += sums2[from];
    }
  float mean[kMaxBands], var[kMaxBands];
  pixel_moments(p, n_bands, spp, exposure, mean, var);
  for (int b = 0; b < n_bands; ++b) {
    image[b * pixels + at] = mean[b];
    variance[b * pixels + at] = var[b];
  }
}

// Threads per pixel: enough for every multiprocessor's full complement of
// threads, never more than the samples (each share traces at least one).
int threads_per_pixel(const TruthInputs& in, long long pixels) {
  if (in.gpu_threads_per_pixel > 0) return std::min(in.gpu_threads_per_pixel, in.spp);
  int device = 0, sms = 0, per_sm = 0;
  NEBULA_CUDA_CHECK(cudaGetDevice(&device));
  NEBULA_CUDA_CHECK(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device));
  NEBULA_CUDA_CHECK(cudaDeviceGetAttribute(&per_sm, cudaDevAttrMaxThreadsPerMultiProcessor, device));
  const long long wanted = static_cast<long long>(sms) * per_sm;
  const long long shares = (wanted + pixels - 1) / pixels;
  return static_cast<int>(std::clamp<long long>(shares, 1, in.spp));
}

}  // namespace

TruthOutput render_truth_cuda(const TruthInputs& in) {
  validate(in);
  const MajorantGrid majorant = build_majorant_grid(*in.density, in.majorant_block);
  DevicePlacement device;
  const PathScene scene = assemble_path_scene(in, majorant, device);
  TruthOutput out;
  out.image = Image(in.camera.width, in.camera.height, band_names(in.bands));
  out.variance = Image(in.camera.width, in.camera.height, band_names(in.bands));
  const long long pixels = static_cast<long long>(in.camera.width) * in.camera.height;
  const int shares = threads_per_pixel(in, pixels);
  const size_t sum_count = shares > 1 ? size_t(shares) * size_t(scene.n_bands) * size_t(pixels) : 0;
  DeviceArray<double> sums(sum_count), sums2(sum_count);
  DeviceArray<float> image(out.image.pixels.size()), variance(out.variance.pixels.size());
  DeviceArray<unsigned long long> counters(4);
  constexpr int kBlock = 128;
  const long long threads = pixels * shares;
  CudaEventTimer timer;
  truth_samples_kernel<<<static_cast<unsigned>((threads + kBlock - 1) / kBlock), kBlock>>>(
      scene, in.camera, in.exposure, in.spp, shares, sums.get(), sums2.get(), image.get(), variance.get(),
      counters.get());
  NEBULA_CUDA_CHECK(cudaGetLastError());
  if (shares > 1)
    truth_moments_kernel<<<static_cast<unsigned>((pixels + kBlock - 1) / kBlock), kBlock>>>(
        scene.n_bands, pixels, in.spp, shares, in.exposure, sums.get(), sums2.get(), image.get(), variance.get());
  NEBULA_CUDA_CHECK(cudaGetLastError());
  out.seconds = timer.seconds();
  image.download(out.image.pixels.data());
  variance.download(out.variance.pixels.data());
  unsigned long long c[4] = {};
  counters.download(c);
  out.counters.vertices = c[0];
  out.counters.tentative = c[1];
  out.counters.capped = c[2];
  out.paths = uint64_t(c[3]) * uint64_t(in.spp) * in.bands.size();
  out.threads_per_pixel = shares;
  return out;
}

}  // namespace nebula
