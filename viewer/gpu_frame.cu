// CUDA side of viewer/gpu_frame.h: render on the device, tone-map there, and
// hand the RGBA8 pixels to OpenGL through a registered pixel buffer.
#include <GL/gl.h>
#include <cuda_gl_interop.h>
#include <cuda_runtime.h>

#include <cmath>

#include "core/cuda_check.h"
#include "core/cuda_timer.h"
#include "core/device_array.h"
#include "core/error.h"
#include "core/gpu.h"
#include "viewer/gpu_frame.h"

namespace nebula::viewer {
namespace {

struct DeviceDisplay {
  int stretch;  // 0 linear, 1 asinh, 2 log
  float exposure, white, softening, norm;  // norm: asinh(1/s) or ln(1 + 1/s)
  int red, green, blue;                    // source planes, -1: none
};

__device__ unsigned char level(float value, const DeviceDisplay& d) {
  const float x = value * d.exposure;
  if (!(x > 0.0f)) return 0;
  const float r = x / d.white;
  float y = r;
  if (d.stretch == 1) y = asinhf(r / d.softening) / d.norm;
  if (d.stretch == 2) y = log1pf(r / d.softening) / d.norm;
  y = fminf(y, 1.0f);
  const float encoded = y <= 0.0031308f ? 12.92f * y : 1.055f * powf(y, 1.0f / 2.4f) - 0.055f;
  return static_cast<unsigned char>(lrintf(255.0f * encoded));
}

__global__ void tone_map_kernel(const float* pixels, int width, int height, DeviceDisplay d, uchar4* out) {
  const int x = blockIdx.x * blockDim.x + threadIdx.x, y = blockIdx.y * blockDim.y + threadIdx.y;
  if (x >= width || y >= height) return;
  const size_t plane = size_t(width) * height, i = size_t(y) * width + x;
  uchar4 p;
  p.x = d.red < 0 ? 0 : level(pixels[d.red * plane + i], d);
  p.y = d.green < 0 ? 0 : level(pixels[d.green * plane + i], d);
  p.z = d.blue < 0 ? 0 : level(pixels[d.blue * plane + i], d);
  p.w = 255;
  out[i] = p;
}

DeviceDisplay device_display(const RenderInputs& in, double exposure, const DisplaySettings& s) {
  DeviceDisplay d;
  d.stretch = s.stretch == Stretch::Asinh ? 1 : s.stretch == Stretch::Log ? 2 : 0;
  d.exposure = float(exposure);
  d.white = float(s.white);
  d.softening = float(s.softening);
  d.norm = float(s.stretch == Stretch::Asinh ? std::asinh(1.0 / s.softening) : std::log1p(1.0 / s.softening));
  auto plane = [&](const char* name) {
    for (size_t b = 0; b < in.bands.size(); ++b)
      if (in.bands[b].name == name) return int(b);
    return -1;
  };
  if (in.bands.size() == 1) {
    d.red = d.green = d.blue = 0;
  } else {
    d.red = plane("R");
    d.green = plane("V");
    d.blue = plane("B");
  }
  return d;
}

}  // namespace

struct GpuFrame::Impl {
  std::unique_ptr<DeviceArray<float>> pixels;
  std::unique_ptr<DeviceArray<uchar4>> rgba;
  DeviceArray<unsigned long long> clamps{1};
  unsigned pbo = 0;
  cudaGraphicsResource* resource = nullptr;

  ~Impl() {
    if (resource) cudaGraphicsUnregisterResource(resource);
  }

  // Renders and tone-maps into `out`; the GPU time.
  double run(const RenderInputs& in, double exposure, const DisplaySettings& display, uchar4* out) {
    const int w = in.camera.width, h = in.camera.height;
    const size_t count = size_t(w) * h * in.bands.size();
    if (!pixels || pixels->size() != count) pixels = std::make_unique<DeviceArray<float>>(count);
    NEBULA_CUDA_CHECK(cudaMemset(pixels->get(), 0, count * sizeof(float)));
    CudaEventTimer timer;
    render_cuda_to_device(in, pixels->get(), clamps.get());
    const dim3 block(16, 16), grid((w + 15) / 16, (h + 15) / 16);
    tone_map_kernel<<<grid, block>>>(pixels->get(), w, h, device_display(in, exposure, display), out);
    NEBULA_CUDA_CHECK(cudaGetLastError());
    return timer.seconds();
  }
};

bool GpuFrame::available() { return gpu_available(); }

GpuFrame::GpuFrame() : impl_(std::make_unique<Impl>()) {}
GpuFrame::~GpuFrame() = default;

double GpuFrame::render_to_gl(const RenderInputs& in, double exposure, const DisplaySettings& display, unsigned pbo) {
  if (impl_->pbo != pbo) {
    if (impl_->resource) NEBULA_CUDA_CHECK(cudaGraphicsUnregisterResource(impl_->resource));
    impl_->resource = nullptr;
    NEBULA_CUDA_CHECK(cudaGraphicsGLRegisterBuffer(&impl_->resource, pbo, cudaGraphicsRegisterFlagsWriteDiscard));
    impl_->pbo = pbo;
  }
  NEBULA_CUDA_CHECK(cudaGraphicsMapResources(1, &impl_->resource));
  void* mapped = nullptr;
  size_t bytes = 0;
  NEBULA_CUDA_CHECK(cudaGraphicsResourceGetMappedPointer(&mapped, &bytes, impl_->resource));
  const size_t need = size_t(in.camera.width) * in.camera.height * 4;
  double seconds = 0;
  if (bytes >= need) seconds = impl_->run(in, exposure, display, static_cast<uchar4*>(mapped));
  NEBULA_CUDA_CHECK(cudaGraphicsUnmapResources(1, &impl_->resource));
  if (bytes < need) throw Error("nebula-view: the pixel buffer is smaller than the frame");
  return seconds;
}

double GpuFrame::render_to_device(const RenderInputs& in, double exposure, const DisplaySettings& display) {
  const size_t n = size_t(in.camera.width) * in.camera.height;
  if (!impl_->rgba || impl_->rgba->size() != n) impl_->rgba = std::make_unique<DeviceArray<uchar4>>(n);
  const double seconds = impl_->run(in, exposure, display, impl_->rgba->get());
  NEBULA_CUDA_CHECK(cudaDeviceSynchronize());
  return seconds;
}

}  // namespace nebula::viewer
