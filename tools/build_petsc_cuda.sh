#!/usr/bin/env bash
# Builds a CUDA-enabled PETSc from Debian's own PETSc source package (the same 3.18 as the
# libpetsc-real3.18-dev the host build uses), against Debian's OpenMPI, BLAS/LAPACK and HDF5,
# with the machine's nvcc, downloading nothing but Debian's source package. For clusters: run it
# once, then configure morphogen with PETSC_DIR=PREFIX (see README, GPU).
# Usage: tools/build_petsc_cuda.sh [PREFIX] [CUDA_ARCH]   (default /opt/petsc-3.18-cuda, 90)
# Needs root for apt (a deb-src entry for the system's suite is added if missing).
set -euo pipefail
prefix=${1:-/opt/petsc-3.18-cuda}
arch=${2:-90}
work=${WORK:-/tmp/petsc-cuda-build}
nvcc=${NVCC:-$(command -v nvcc || echo /usr/local/cuda/bin/nvcc)}
[ -x "$nvcc" ] || { echo "build_petsc_cuda.sh: nvcc not found (set NVCC)" >&2; exit 1; }
if ! grep -rqs "deb-src" /etc/apt/sources.list /etc/apt/sources.list.d/; then
  sed 's/^Types: deb$/Types: deb-src/' /etc/apt/sources.list.d/debian.sources \
    >/etc/apt/sources.list.d/debian-src.sources
  apt-get update -qq
fi
apt-get install -y -qq libopenmpi-dev liblapack-dev libblas-dev libhdf5-openmpi-dev python3 \
  make >/dev/null
mkdir -p "$work" && cd "$work"
compgen -G 'petsc_*.dsc' >/dev/null || apt-get source -qq --download-only petsc
first_source_dir() { find . -maxdepth 1 -type d -name 'petsc-3.18*' -printf '%f/\n' | sort | head -1; }
src=$(first_source_dir)
if [ -z "$src" ]; then
  tar -xf petsc_*.orig.tar.xz
  src=$(first_source_dir)
fi
cd "$src"
# PETSc 3.18 supports CUDA up to 11.8 (its configure refuses newer ones): its aijcusparse uses
# cusparse?csrsv2_* (removed in CUDA 12) and its device code reads cudaDeviceProp::clockRate
# (removed in CUDA 13). With a newer nvcc, say so before configure does.
cuda_version=$("$nvcc" --version | sed -n 's/.*release \([0-9]*\.[0-9]*\).*/\1/p')
if [[ "$src" == petsc-3.18* ]] && [ "${cuda_version%%.*}" -gt 11 ]; then
  echo "build_petsc_cuda.sh: PETSc ${src%/} supports CUDA <= 11.8, this nvcc is CUDA $cuda_version" \
    "(3.18 calls cusparse csrsv2 functions removed in CUDA 12 and reads cudaDeviceProp::clockRate," \
    "removed in CUDA 13): use a CUDA 11.8 toolkit (NVCC=...) or a PETSc >= 3.19 source" >&2
  exit 1
fi
# CUDA 12 and later ship NVTX only as the header-only NVTX3 (no libnvToolsExt, no top-level
# nvToolsExt.h), which PETSc 3.18 expects: a shim header forwards to nvtx3/, and the CUDA
# libraries are given explicitly so configure does not look for libnvToolsExt.
shim=$work/nvtx-shim
mkdir -p "$shim"
echo '#include <nvtx3/nvToolsExt.h>' >"$shim/nvToolsExt.h"
cuda=$(dirname "$(dirname "$nvcc")")
echo "PETSc source: $work/$src; nvcc: $("$nvcc" --version | tail -1)"
python3 ./configure --prefix="$prefix" PETSC_ARCH=arch-cuda \
  --with-debugging=0 COPTFLAGS=-O2 CXXOPTFLAGS=-O2 CUDAOPTFLAGS=-O2 \
  --with-cc=mpicc --with-cxx=mpicxx --with-fc=0 \
  --with-cuda=1 --with-cudac="$nvcc" --with-cuda-arch="$arch" \
  --with-cuda-include="[$cuda/include,$shim]" \
  --with-cuda-lib="[-L$cuda/lib64,-lcudart,-lcufft,-lcublas,-lcusparse,-lcusolver,-lcurand,-L$cuda/lib64/stubs,-lcuda]" \
  --with-blaslapack-lib="-llapack -lblas" \
  --with-hdf5=1 --with-hdf5-include=/usr/include/hdf5/openmpi \
  --with-hdf5-lib="-L/usr/lib/x86_64-linux-gnu/hdf5/openmpi -lhdf5" \
  --with-x=0 --with-ssl=0
make PETSC_DIR="$PWD" PETSC_ARCH=arch-cuda all
make PETSC_DIR="$PWD" PETSC_ARCH=arch-cuda install
echo "CUDA PETSc installed in $prefix"
