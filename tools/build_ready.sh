#!/usr/bin/env bash
# Builds Ready's command-line utility rdy (https://github.com/GollyGang/ready, the comparison
# of postproc/vs_ready.py) on Debian 12 without its wxWidgets GUI, against ParaView's VTK
# (paraview-dev: Debian's libvtk9-dev conflicts with the python3-paraview morphogen uses) and
# PoCL's CPU OpenCL. Ready is not a dependency of morphogen; this is only for the comparison.
# Usage: tools/build_ready.sh READY_SOURCE_DIR [BUILD_DIR]   (default BUILD_DIR /tmp/ready-rdy)
# READY_SOURCE_DIR is a checkout of Ready (its src/ is read, never changed). Needs root for apt.
# Two edits of the copied sources, both outside the simulation code: VTK 9.2 dropped
# vtkThreshold::ThresholdByUpper (the same filter set by SetLowerThreshold + THRESHOLD_UPPER),
# and ParaView's VTK has no ImagingStencil module, used only to voxelise a mesh into an image
# (that function now throws). Then: postproc/vs_ready.py --rdy BUILD_DIR/build/rdy
# PoCL, once installed, is loaded into Open MPI's mpiexec by hwloc's OpenCL plugin and takes
# SIGUSR1 from it: signal such an mpiexec with HWLOC_COMPONENTS=-opencl,-gl set (README).
set -euo pipefail
src=${1:?usage: tools/build_ready.sh READY_SOURCE_DIR [BUILD_DIR]}
work=${2:-/tmp/ready-rdy}
[ -f "$src/src/readybase/ImageRD.cpp" ] || {
  echo "build_ready.sh: $src/src/readybase/ImageRD.cpp not found (not a Ready checkout)" >&2
  exit 1
}
packages=(build-essential cmake paraview-dev pocl-opencl-icd ocl-icd-opencl-dev opencl-headers
  libglew-dev)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi
mkdir -p "$work/src"
rm -rf "$work/src/readybase" "$work/src/cmd" "$work/src/extern"
cp -r "$src/src/readybase" "$src/src/cmd" "$src/src/extern" "$work/src/"
rb="$work/src/readybase"
sed -i 's/\bthreshold->ThresholdByUpper(\([^)]*\));/threshold->SetLowerThreshold(\1); threshold->SetThresholdFunction(vtkThreshold::THRESHOLD_UPPER);/' \
  "$rb/ImageRD.cpp" "$rb/MeshRD.cpp"
sed -i -e '/#include <vtkImageStencil.h>/d' -e '/#include <vtkPolyDataToImageStencil.h>/d' \
  -e '/vtkPolyDataToImageStencil> pol2stenc =/,/DeepCopy(imgstenc->GetOutput());/c\    throw std::runtime_error("voxelising a mesh needs VTK ImagingStencil (not in this build)");' \
  "$rb/ImageRD.cpp"
vtk_dir=$(dirname "$(find /usr/lib -path "*/cmake/paraview-*/vtk/vtk-config.cmake" | head -1)")
[ -f "$vtk_dir/vtk-config.cmake" ] || { echo "build_ready.sh: ParaView's vtk-config.cmake not found (paraview-dev)" >&2; exit 1; }
cat >"$work/CMakeLists.txt" <<EOF
cmake_minimum_required(VERSION 3.16)
project(rdy CXX C)
set(CMAKE_CXX_STANDARD 17)
file(GLOB BASE \${CMAKE_SOURCE_DIR}/src/readybase/*.cpp \${CMAKE_SOURCE_DIR}/src/readybase/*.c)
set(MODS CommonColor CommonCore FiltersCore FiltersExtraction FiltersGeometry FiltersModeling
  FiltersSources FiltersTexture ImagingColor IOImage IOGeometry IOPLY IOXML RenderingCore
  RenderingAnnotation RenderingFreeType RenderingOpenGL2 InteractionStyle)
find_package(VTK REQUIRED PATHS $vtk_dir NO_DEFAULT_PATH COMPONENTS \${MODS})
find_package(OpenCL REQUIRED)
list(TRANSFORM MODS PREPEND VTK::)
add_library(readybase STATIC \${BASE})
target_include_directories(readybase PUBLIC \${CMAKE_SOURCE_DIR}/src/readybase
  \${CMAKE_SOURCE_DIR}/src/extern)
target_link_libraries(readybase \${MODS} OpenCL::OpenCL)
vtk_module_autoinit(TARGETS readybase MODULES \${MODS})
add_executable(rdy \${CMAKE_SOURCE_DIR}/src/cmd/main.cpp)
target_include_directories(rdy PRIVATE \${CMAKE_SOURCE_DIR}/src/extern/cxxopts-2.2.1)
target_link_libraries(rdy readybase \${CMAKE_DL_LIBS})
EOF
cmake -S "$work" -B "$work/build" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$work/build" -j "$(nproc)"
echo "build_ready.sh: built $work/build/rdy"
