#include "grid/stencil.hpp"

namespace morphogen {

bool make_stencil(const std::string& name, int dim, const double* h, Stencil& s) {
  Stencil r;
  r.name = name;
  if ((name == "5pt" && dim == 2) || (name == "7pt" && dim == 3)) {
    double centre = 0;
    for (int d = 0; d < dim; ++d)
      centre -= 2.0 / (h[d] * h[d]);
    r.add(0, 0, 0, centre);
    for (int d = 0; d < dim; ++d) {
      const double w = 1.0 / (h[d] * h[d]);
      int o[3] = {0, 0, 0};
      o[d] = -1;
      r.add(o[0], o[1], o[2], w);
      o[d] = 1;
      r.add(o[0], o[1], o[2], w);
    }
  } else if (name == "9pt" && dim == 2) {
    if (std::abs(h[0] - h[1]) > 1e-12 * h[0]) return false;
    const double s6 = 1.0 / (6.0 * h[0] * h[0]);
    r.add(0, 0, 0, -20.0 * s6);
    r.add(-1, 0, 0, 4.0 * s6);
    r.add(1, 0, 0, 4.0 * s6);
    r.add(0, -1, 0, 4.0 * s6);
    r.add(0, 1, 0, 4.0 * s6);
    r.add(-1, -1, 0, s6);
    r.add(1, -1, 0, s6);
    r.add(-1, 1, 0, s6);
    r.add(1, 1, 0, s6);
  } else if ((name == "19pt" || name == "27pt") && dim == 3) {
    if (std::abs(h[0] - h[1]) > 1e-12 * h[0] || std::abs(h[0] - h[2]) > 1e-12 * h[0]) return false;
    // Weights of the centre, face, edge and corner neighbours (count of nonzero offsets).
    const bool full = name == "27pt";
    const double sc = 1.0 / ((full ? 30.0 : 6.0) * h[0] * h[0]);
    const double w[4] = {full ? -128.0 : -24.0, full ? 14.0 : 2.0, full ? 3.0 : 1.0,
                         full ? 1.0 : 0.0};
    r.add(0, 0, 0, w[0] * sc);
    for (int o = 0; o < 27; ++o) {
      const int dx = o % 3 - 1, dy = (o / 3) % 3 - 1, dz = o / 9 - 1;
      const int k = (dx != 0) + (dy != 0) + (dz != 0);
      if (k > 0 && w[k] != 0.0) r.add(dx, dy, dz, w[k] * sc);
    }
  } else {
    return false;
  }
  s = r;
  return true;
}

bool to_rows(const Stencil& s, RowStencil& out) {
  RowStencil r;
  r.off[0] = {0, 0};
  r.nrows = 1;
  for (int t = 0; t < s.nterms; ++t) {
    const int dx = s.off[t][0];
    if (dx < -1 || dx > 1) return false;
    int row = -1;
    for (int q = 0; q < r.nrows; ++q)
      if (r.off[q][0] == s.off[t][1] && r.off[q][1] == s.off[t][2]) row = q;
    if (row < 0) {
      row = r.nrows++;
      r.off[row] = {s.off[t][1], s.off[t][2]};
    }
    r.w[3 * row + dx + 1] += s.w[t];
    if (row > 0 && dx != 0) r.box = true;
  }
  out = r;
  return true;
}

bool box_classes(const RowStencil& rows, BoxClasses& out) {
  const int n = rows.nrows; // 3: 2-D (dz = 0), 9: 3-D
  if ((n != 3 && n != 9) || !rows.box || rows.off[0][0] != 0 || rows.off[0][1] != 0) return false;
  BoxClasses c;
  std::array<bool, 4> seen{};
  int faces = 0, corners = 0, covered = 0; // covered: bit per (dy, dz) of the 3x3 rows
  for (int r = 0; r < n; ++r) {
    const int dy = rows.off[r][0], dz = rows.off[r][1];
    if (dy < -1 || dy > 1 || dz < -1 || dz > 1) return false;
    covered |= 1 << (3 * (dz + 1) + dy + 1);
    const int yz = (dy != 0) + (dz != 0);
    if (yz == 1 && faces < 4) c.perm[1 + faces++] = r;
    if (yz == 2 && corners < 4) c.perm[5 + corners++] = r;
    for (int dx = -1; dx <= 1; ++dx) {
      const int k = yz + (dx != 0);
      const double w = rows.w[3 * r + dx + 1];
      if (seen[k] && w != c.w[k]) return false;
      seen[k] = true;
      c.w[k] = w;
    }
  }
  const bool whole = n == 9 ? covered == 0x1ff && faces == 4 && corners == 4
                            : covered == 0x38 && faces == 2; // the rows dz = 0, dy = -1, 0, 1
  if (!whole) return false;
  out = c;
  return true;
}

bool to_class_order(RowStencil& rows, BoxClasses& out) {
  if (!box_classes(rows, out)) return false;
  const RowStencil given = rows;
  for (int q = 0; q < rows.nrows; ++q) {
    const int g = out.perm[q];
    rows.off[q] = given.off[g];
    for (int c = 0; c < 3; ++c)
      rows.w[3 * q + c] = given.w[3 * g + c];
  }
  return true;
}

} // namespace morphogen
