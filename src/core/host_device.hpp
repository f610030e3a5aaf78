// MG_HD marks a pure function for both host and device: __host__ __device__ under nvcc, nothing
// in the C++ build. Kernels (models, *_kernel.hpp) use it so the CUDA path compiles the same code.
#pragma once

#if defined(__CUDACC__)
#define MG_HD __host__ __device__
#else
#define MG_HD
#endif
