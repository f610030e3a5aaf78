#include "fields/strokes_field.hpp"

#include "core/user_error.hpp"
#include "fields/strokes_file.hpp"
#include "fields/strokes_raster_kernel.hpp"

#include <cmath>
#include <cstdint>
#include <map>
#include <tuple>

namespace morphogen {

StrokeField compute_stroke_field(const std::vector<StrokePolyline>& strokes, const FmmGrid& g,
                                 StrokeAngle mode) {
  const size_t n = static_cast<size_t>(g.nx) * static_cast<size_t>(g.ny);
  const int ncomp = mode == StrokeAngle::Axial ? 2 : 4;
  std::vector<double> T(n, INFINITY), F(n * static_cast<size_t>(ncomp), 0.0);
  std::vector<std::uint8_t> state(n, kFmmFar);
  const double band = std::fmax(g.hx, g.hy);
  for (const StrokePolyline& s : strokes)
    rasterise_polyline(g, band, s.data(), static_cast<int>(s.size() / 2), ncomp, T.data(),
                       state.data(), F.data());
  {
    std::vector<int> heap(n), pos(n);
    std::vector<double> key(n);
    fast_marching(g, T.data(), state.data(), F.data(), ncomp, heap.data(), key.data(), pos.data());
  }
  StrokeField out;
  out.nx = g.nx;
  out.ny = g.ny;
  out.theta.resize(n);
  for (size_t c = 0; c < n; ++c)
    out.theta[c] = mode == StrokeAngle::Axial ? 0.5 * std::atan2(F[2 * c + 1], F[2 * c])
                                              : std::atan2(F[4 * c + 3], F[4 * c + 2]);
  out.distance = std::move(T);
  return out;
}

namespace {

using CacheKey = std::tuple<std::string, int, int, double, double, bool, bool, int>;

// The most recent fields (a run names a few files; a sweep's runs differ in grid).
constexpr size_t kCacheEntries = 4;

} // namespace

std::shared_ptr<const StrokeField> cached_stroke_field(const std::string& path, const FmmGrid& g,
                                                       StrokeAngle mode) {
  static std::vector<std::pair<CacheKey, std::shared_ptr<const StrokeField>>> cache;
  const std::string text = read_stroke_file_text(path);
  const CacheKey key{text, g.nx,         g.ny,         g.hx,
                     g.hy, g.periodic_x, g.periodic_y, static_cast<int>(mode)};
  for (const auto& [k, f] : cache)
    if (k == key) return f;
  const std::vector<StrokePolyline> strokes =
      parse_strokes(path, text, g.nx * g.hx, g.ny * g.hy, g.hx, g.hy);
  auto field = std::make_shared<const StrokeField>(compute_stroke_field(strokes, g, mode));
  if (std::isinf(field->distance[0])) // the grid is connected: no cell reached, no seed
    throw UserError("strokes file " + path + ": no stroke passes within one cell of the domain");
  if (cache.size() >= kCacheEntries) cache.erase(cache.begin());
  cache.emplace_back(key, field);
  return field;
}

} // namespace morphogen
