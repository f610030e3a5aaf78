#!/usr/bin/env bash
# Packs morphogen-gpu-check with the shared libraries it needs (libstdc++, libgcc_s and glibc with
# its loader, so it also runs on a machine with an older C library) into one tarball for a bare
# GPU machine (no PETSc, MPI or CUDA toolkit; only the NVIDIA driver). The CUDA runtime is linked
# statically. Usage: tests/gpu/pack_gpu_check.sh BUILD_DIR [TARBALL]
#   default TARBALL: BUILD_DIR/morphogen-gpu-check.tar.gz
set -euo pipefail
build=${1:?usage: pack_gpu_check.sh BUILD_DIR [TARBALL]}
tarball=${2:-$build/morphogen-gpu-check.tar.gz}
bin=$build/morphogen-gpu-check
[ -x "$bin" ] || { echo "pack_gpu_check.sh: $bin not found (configure with nvcc on PATH and build the target morphogen-gpu-check)" >&2; exit 1; }
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/gpu-check/bin" "$stage/gpu-check/lib"
cp "$bin" "$stage/gpu-check/bin/"
cp "$(dirname "$0")/run_on_gpu.sh" "$stage/gpu-check/"
# Every library ldd names, and the loader.
ldd "$bin" | awk '/=> \// {print $3} /ld-linux/ && !/=>/ {print $1}' | while read -r lib; do
  cp -L "$lib" "$stage/gpu-check/lib/"
done
tar -C "$stage" -czf "$tarball" gpu-check
echo "$tarball: $(du -h "$tarball" | cut -f1) ($(ls "$stage/gpu-check/lib" | tr '\n' ' '))"
