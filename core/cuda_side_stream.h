#pragma once
// A second stream, of the highest priority, for a small launch that runs
// beside the main one instead of after it: the rays near a star, which the
// marchers take the phase's mean over the chord's angles for (tables/chord_phase.h;
// raycast/renderer_cuda.cu, spectral/spectral_renderer_cuda.cu). A few thousand
// rays marched alone cost about one ray's latency through the grid, most of a
// frame's wave (H100: 0.6-0.7 ms of a 5.1 ms frame, docs/performance.md);
// beside the main launch they fill multiprocessor slots it leaves free.
// Include only from .cu files.
#include <cuda_runtime.h>

#include "core/cuda_check.h"

namespace nebula {

struct SideStream {
  cudaStream_t stream = nullptr;
  cudaEvent_t ready = nullptr, done = nullptr;
  void start() {
    if (!stream) {
      // The highest priority: its blocks start first, beside the main
      // launch's, instead of making its tail (6.97-6.98 ms against 6.98-7.61 ms
      // at the default priority for the 1080p frame with the field, H100).
      int least = 0, greatest = 0;
      NEBULA_CUDA_CHECK(cudaDeviceGetStreamPriorityRange(&least, &greatest));
      NEBULA_CUDA_CHECK(cudaStreamCreateWithPriority(&stream, cudaStreamNonBlocking, greatest));
      NEBULA_CUDA_CHECK(cudaEventCreateWithFlags(&ready, cudaEventDisableTiming));
      NEBULA_CUDA_CHECK(cudaEventCreateWithFlags(&done, cudaEventDisableTiming));
    }
    // Whatever the default stream queued before (the field's light) comes first.
    NEBULA_CUDA_CHECK(cudaEventRecord(ready, 0));
    NEBULA_CUDA_CHECK(cudaStreamWaitEvent(stream, ready, 0));
  }
  // The default stream's later work (the timer's stop, the download) waits for it.
  void join() {
    NEBULA_CUDA_CHECK(cudaEventRecord(done, stream));
    NEBULA_CUDA_CHECK(cudaStreamWaitEvent(0, done, 0));
  }
  ~SideStream() {
    if (stream) {
      cudaEventDestroy(ready);
      cudaEventDestroy(done);
      cudaStreamDestroy(stream);
    }
  }
};

}  // namespace nebula
