#pragma once
// The viewer's frame on the GPU: the CUDA ray marcher's pixels (raycast/
// render_cuda_to_device) tone-mapped on the device to 8-bit RGBA with the
// display transform of core/display.h, written straight into an OpenGL pixel
// buffer registered with CUDA (CUDA-OpenGL interop: no round trip through the
// host), or into device memory for benchmarks without a window. Built with
// CUDA only; available() says so. The tone map runs in single precision, so a
// level may differ by one from the host's (the PNG writer's) double-precision curve.
#include <memory>

#include "core/display.h"
#include "raycast/renderer.h"

namespace nebula::viewer {

class GpuFrame {
 public:
  static bool available();  // built with CUDA and a device is usable
  GpuFrame();
  ~GpuFrame();
  GpuFrame(const GpuFrame&) = delete;
  GpuFrame& operator=(const GpuFrame&) = delete;

  // Renders in.camera and tone-maps it into the OpenGL pixel-unpack buffer
  // `pbo` (at least width x height x 4 bytes; the GL context current on this
  // thread). Returns the GPU time in seconds (CUDA events). Throws Error.
  double render_to_gl(const RenderInputs& in, double exposure, const DisplaySettings& display, unsigned pbo);
  // The same into device memory held here.
  double render_to_device(const RenderInputs& in, double exposure, const DisplaySettings& display);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace nebula::viewer
