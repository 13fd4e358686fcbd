#pragma once
// NEBULA_HD marks functions compiled for both host and device: physics is
// written once and called from TBB on the CPU and from CUDA kernels.
#if defined(__CUDACC__)
#define NEBULA_HD __host__ __device__ inline
#define NEBULA_DEVICE_CODE 1
#else
#define NEBULA_HD inline
#endif

// True inside the device pass of nvcc, where host-only facilities are absent.
#if defined(__CUDA_ARCH__)
#define NEBULA_ON_DEVICE 1
#else
#define NEBULA_ON_DEVICE 0
#endif

// Before a loop over bands (b < kMaxBands, leaving early past the scene's
// count): fully unrolled on the device, so per-band arrays stay in registers
// instead of the stack.
#if defined(__CUDACC__)
#define NEBULA_UNROLL _Pragma("unroll")
#else
#define NEBULA_UNROLL
#endif
