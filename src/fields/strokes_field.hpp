// Orientation and distance fields of a set of polyline strokes (stable-ARD section 6): the strokes
// are rasterised with their direction (strokes_raster_kernel.hpp), then first-order fast marching
// with extension velocities (fast_marching_kernel.hpp) carries the orientation of the nearest
// stroke to every cell of the x-y grid.
//
// Orientation is an axis (angle mod pi): the march extends (cos 2 phi, sin 2 phi) and
// theta = atan2(sin, cos) / 2 in (-pi/2, pi/2] (StrokeAngle::Axial); a direction along the drawing
// (angle mod 2 pi, for a single cosine lobe) extends (cos phi, sin phi) and theta = atan2 in
// (-pi, pi] (StrokeAngle::Directed). Where the extended vector is (0, 0) (opposite directions
// meeting exactly) theta = 0. Seeds: the cells within max(hx, hy) of a stroke, at their exact
// distance. Computed whole on the calling process (no MPI): every rank computes the same bits.
// Memory: 41 bytes per cell while marching, 16 bytes per cell kept.
#pragma once

#include "fields/fast_marching_kernel.hpp"

#include <memory>
#include <string>
#include <vector>

namespace morphogen {

// Largest x-y grid (nx * ny) a stroke field is computed on: 4096^2 cells (every rank holds it).
inline constexpr long kMaxStrokeCells = 4096L * 4096L;

enum class StrokeAngle { Axial, Directed };

// One stroke: x0, y0, x1, y1, ... in domain units (at least two distinct points).
using StrokePolyline = std::vector<double>;

struct StrokeField {
  int nx = 0, ny = 0;
  std::vector<double> distance; // to the nearest stroke, domain units (+inf where unreachable)
  std::vector<double> theta;    // orientation of the nearest stroke (radians), see above
  double distance_at(int i, int j) const { return distance[static_cast<size_t>(i + nx * j)]; }
  double theta_at(int i, int j) const { return theta[static_cast<size_t>(i + nx * j)]; }
};

StrokeField compute_stroke_field(const std::vector<StrokePolyline>& strokes, const FmmGrid& g,
                                 StrokeAngle mode);

// The field of stroke file `path` (strokes_file.hpp) on grid g: read and computed once per
// (file contents, grid, mode) in this process and shared by every value that names it.
std::shared_ptr<const StrokeField> cached_stroke_field(const std::string& path, const FmmGrid& g,
                                                       StrokeAngle mode);

} // namespace morphogen
