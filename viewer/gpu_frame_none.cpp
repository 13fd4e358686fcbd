// A build without CUDA: no GPU frame (the viewer renders on the CPU).
#include "viewer/gpu_frame.h"

#include "core/error.h"

namespace nebula::viewer {

struct GpuFrame::Impl {};
bool GpuFrame::available() { return false; }
GpuFrame::GpuFrame() = default;
GpuFrame::~GpuFrame() = default;
double GpuFrame::render_to_gl(const RenderInputs&, double, const DisplaySettings&, unsigned) {
  throw Error("nebula-view: built without CUDA: no GPU frame");
}
double GpuFrame::render_to_device(const RenderInputs&, double, const DisplaySettings&) {
  throw Error("nebula-view: built without CUDA: no GPU frame");
}

}  // namespace nebula::viewer
