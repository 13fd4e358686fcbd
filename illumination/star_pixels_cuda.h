#pragma once
// The star pixels' store on the GPU (illumination/star_pixels.h), for the
// marchers' CUDA files: the two steps, each one thread per (cell, plane), on
// the default stream after the star pixels' rays and the image's launches.
// Include from .cu files only.
#include <cuda_runtime.h>

#include "illumination/star_pixels.h"

namespace nebula {
namespace {

__global__ void reduce_star_cells_kernel(float* sub, int rays, const StarPixel* list, int n, int n_planes) {
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  if (t < n * n_planes) reduce_star_cell(sub, size_t(rays), list, t % n, t / n);
}

__global__ void store_star_pixels_kernel(const float* sub, int rays, const StarPixel* list, int n, int n_planes,
                                         float exposure, float* pixels, int width, int height) {
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  if (t < n * n_planes) store_star_pixel(sub, size_t(rays), list, t % n, t / n, exposure, pixels, width, height);
}

// Stores the n cells' pixels (list on the device) from their rays' values
// `sub` (changed: each cell's mean over its first ray's value).
inline void store_star_pixels_cuda(const StarPixel* list, int n, float* sub, int rays, int n_planes, float exposure,
                                   float* pixels, int width, int height) {
  const unsigned blocks = unsigned((n * n_planes + 127) / 128);
  reduce_star_cells_kernel<<<blocks, 128>>>(sub, rays, list, n, n_planes);
  store_star_pixels_kernel<<<blocks, 128>>>(sub, rays, list, n, n_planes, exposure, pixels, width, height);
}

}  // namespace
}  // namespace nebula
