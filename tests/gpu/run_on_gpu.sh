#!/usr/bin/env bash
# The GPU check on a machine with an NVIDIA GPU and no PETSc or MPI: unpacks the tarball made by
# tests/gpu/pack_gpu_check.sh, runs morphogen-gpu-check (GPU vs CPU checks, then the bench) and
# writes everything to RESULT_DIR/gpu_check.txt and RESULT_DIR/gpu_check.json. Takes about a
# minute on an H200. Exit: 0 checks pass, 1 a check failed, 77 no CUDA device.
# Usage: run_on_gpu.sh TARBALL RESULT_DIR [--quick]
set -uo pipefail
tarball=${1:?usage: run_on_gpu.sh TARBALL RESULT_DIR [--quick]}
out=${2:?usage: run_on_gpu.sh TARBALL RESULT_DIR [--quick]}
shift 2
mkdir -p "$out"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
tar -C "$work" -xzf "$tarball" || { echo "run_on_gpu.sh: cannot unpack $tarball" >&2; exit 1; }
dir=$work/gpu-check
log=$out/gpu_check.txt
{
  echo "== $(date -u +%FT%TZ) on $(hostname)"
  command -v nvidia-smi >/dev/null && nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv,noheader
} >"$log" 2>&1
# The binary with the system's C library first; if that C library is too old for it, with the
# bundled loader and libraries (the driver's libcuda is still found by the loader's search).
run() { "$dir/bin/morphogen-gpu-check" --out "$out/gpu_check.json" "$@"; }
run_bundled() {
  "$dir/lib/ld-linux-x86-64.so.2" --library-path "$dir/lib:/usr/lib/x86_64-linux-gnu:/usr/lib64" \
    "$dir/bin/morphogen-gpu-check" --out "$out/gpu_check.json" "$@"
}
if "$dir/bin/morphogen-gpu-check" --probe >/dev/null 2>&1; then
  run "$@" >>"$log" 2>&1
else
  echo "the system C library cannot load the binary: using the bundled one" >>"$log"
  run_bundled "$@" >>"$log" 2>&1
fi
rc=$?
echo "== exit $rc" >>"$log"
cat "$log"
exit $rc
