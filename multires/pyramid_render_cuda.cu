// The pyramid on the GPU: every level rendered into device memory by the ray
// marcher's CUDA path (raycast/renderer.h), then combined there by the same
// per-pixel steps the host uses (pyramid_pixels.h); only the final image (and,
// when asked, the level images) comes back.
#include <cuda_runtime.h>

#include <memory>
#include <vector>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "multires/pyramid_pixels.h"
#include "multires/pyramid_render.h"

namespace nebula {
namespace {

// S_j = max(I_j - down(I_{j-1}), 0) + up(S_{j+1}) over level j's pixels, all bands.
__global__ void pyramid_sum_kernel(const float* level, const float* finer, int w_finer, int h_finer,
                                   const float* coarser, int w_coarser, int h_coarser, int w, int h, int n_bands,
                                   float* sum) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= w || y >= h) return;
  for (int b = 0; b < n_bands; ++b) {
    const size_t plane = size_t(w) * h, plane_finer = size_t(w_finer) * h_finer,
                 plane_coarser = size_t(w_coarser) * h_coarser;
    sum[b * plane + size_t(y) * w + x] =
        pyramid_sum(level + b * plane, finer + b * plane_finer, w_finer, h_finer,
                    coarser ? coarser + b * plane_coarser : nullptr, w_coarser, h_coarser, w, x, y);
  }
}

// image += up(S_1) at full resolution.
__global__ void pyramid_add_kernel(float* image, int w, int h, const float* sum, int w_sum, int h_sum, int n_bands) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= w || y >= h) return;
  for (int b = 0; b < n_bands; ++b)
    image[b * size_t(w) * h + size_t(y) * w + x] += bilinear_up(sum + b * size_t(w_sum) * h_sum, w_sum, h_sum, x, y);
}

dim3 blocks_for(int w, int h, dim3 block) { return dim3((w + block.x - 1) / block.x, (h + block.y - 1) / block.y); }

}  // namespace

PyramidResult render_pyramid_cuda(const RenderInputs& in, const PreparedPyramid& prepared, bool keep_levels) {
  const int n = static_cast<int>(prepared.levels.size());
  const int n_bands = static_cast<int>(in.bands.size());
  PyramidResult out;
  std::vector<std::unique_ptr<DeviceArray<float>>> images;  // I_0 .. I_n on the device
  std::vector<Camera> cameras{in.camera};
  for (int j = 0; j <= n; ++j) {
    if (j > 0) cameras.push_back(coarser_camera(cameras.back()));
    const RenderInputs level_in = j == 0 ? in : level_inputs(in, prepared.levels[j - 1], cameras[j]);
    images.push_back(std::make_unique<DeviceArray<float>>(size_t(n_bands) * cameras[j].width * cameras[j].height));
    DeviceArray<unsigned long long> clamps(1);
    PyramidLevelReport r = j == 0 ? PyramidLevelReport{} : prepared.levels[j - 1].report;
    if (j == 0) r.shape = in.density->shape;
    r.width = cameras[j].width;
    r.height = cameras[j].height;
    r.render_seconds = render_cuda_to_device(level_in, images.back()->get(), clamps.get());
    unsigned long long count = 0;
    clamps.download(&count);
    r.table_clamps = count;
    out.report.push_back(r);
    if (keep_levels) {
      out.levels.emplace_back(cameras[j].width, cameras[j].height, band_names(in.bands));
      images.back()->download(out.levels.back().pixels.data());
    }
  }
  // The combination, coarsest first, entirely on the device.
  const dim3 block(16, 16);
  std::vector<std::unique_ptr<DeviceArray<float>>> sums(n + 1);  // S_1 .. S_n
  for (int j = 1; j <= n; ++j)
    sums[j] = std::make_unique<DeviceArray<float>>(size_t(n_bands) * cameras[j].width * cameras[j].height);
  CudaEventTimer timer;
  for (int j = n; j >= 1; --j) {
    const int w = cameras[j].width, h = cameras[j].height;
    pyramid_sum_kernel<<<blocks_for(w, h, block), block>>>(
        images[j]->get(), images[j - 1]->get(), cameras[j - 1].width, cameras[j - 1].height,
        j < n ? sums[j + 1]->get() : nullptr, j < n ? cameras[j + 1].width : 0, j < n ? cameras[j + 1].height : 0, w,
        h, n_bands, sums[j]->get());
    NEBULA_CUDA_CHECK(cudaGetLastError());
  }
  const Camera& c0 = cameras[0];
  pyramid_add_kernel<<<blocks_for(c0.width, c0.height, block), block>>>(
      images[0]->get(), c0.width, c0.height, sums[1]->get(), cameras[1].width, cameras[1].height, n_bands);
  NEBULA_CUDA_CHECK(cudaGetLastError());
  out.combine_seconds = timer.seconds();
  out.image = Image(c0.width, c0.height, band_names(in.bands));
  images[0]->download(out.image.pixels.data());
  return out;
}

}  // namespace nebula
