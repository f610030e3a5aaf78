// A value given in a deck or on the command line, evaluated at every cell into a field.
//
// Grammar:  VALUE := EXPR [ "+-" AMOUNT ["%"] [uniform | gauss] ]
//   EXPR    a muParser expression. Variables: x y z (cell-centre coordinates), i j k (global
//           cell indices), r and theta (polar radius and angle about the domain centre, in the
//           x-y plane), Lx Ly Lz (domain lengths), nx ny nz (cells), hx hy hz (spacings), t (time,
//           0 at the start). Functions beyond muParser's own:
//             square(cx, cy, half)   1 inside the axis-aligned square of half-width `half`, else 0
//             disk(cx, cy, radius)   1 inside the disk (x-y distance), else 0
//             ball(cx, cy, cz, radius)  1 inside the sphere, else 0
//             spots(n, radius, seed) 1 inside any of n disks (balls in 3-D) whose centres are
//                                    hashed from seed (periodic axes use the minimum image);
//                                    n an integer in [0, kMaxSpots], seed an integer >= 0
//             noise()                uniform deviate in [0,1) of this cell
//             gnoise()               standard normal deviate of this cell
//             png("file.png", lo, hi)  grey level of an image stretched over the domain
//                                    (black = lo, white = hi, bilinear)
//             strokes("file.json")   orientation (radians, mod pi, in (-pi/2, pi/2]) of the
//                                    nearest stroke of a stroke file (.json or .svg, format in
//                                    fields/strokes_file.hpp), extended from the strokes to
//                                    every cell by fast marching (fields/strokes_field.hpp)
//             strokes_directed("file.json")  the same as a direction along the drawing (mod 2 pi,
//                                    in (-pi, pi]), for one-lobe anisotropies
//             strokes_distance("file.json")  distance (domain units) to the nearest stroke
//                                    (e.g. an initial condition: strokes_distance("s.json") < 2)
//           Stroke fields are computed on the x-y grid (at most kMaxStrokeCells cells; in 3-D the
//           same for every z) whole on every rank, once per file and grid (cached).
//   "+-"    perturbation per cell: uniform in [v - a, v + a] (default) or Gaussian with standard
//           deviation a ("gauss"); with "%", a is that percentage of |v| at the cell.
// A value is one expression: a top-level '=' (assignment) or ',' (list) is refused.
// Random deviates hash (seed, key, global cell index): the field is identical on any rank count.
#pragma once

#include "grid/grid.hpp"
#include "io/png_file.hpp"

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace mu {
class Parser;
}

namespace morphogen {
struct StrokeField;
struct ColumnProgram;
} // namespace morphogen

namespace morphogen {

// Cap on spots(n, ...): every cell tests every spot, so n bounds the setup time.
inline constexpr long kMaxSpots = 100000;

// A top-level '=' (assignment) or ',' (list) in a muParser expression: "" if none, else what is
// wrong and what is allowed (for the one-line error).
std::string top_level_problem(const std::string& expr);

// A file named in a value or option: base_dir/file when that exists (a deck's relative names),
// else file as given (relative to the working directory).
std::string resolve_path(const std::string& base_dir, const std::string& file);

class ValueSpec {
public:
  // key: the option name (used in error messages and as the random stream name).
  ValueSpec(const std::string& key, const std::string& text, const GridSpec& grid,
            std::uint64_t seed, const std::string& base_dir = "");
  ~ValueSpec();
  ValueSpec(const ValueSpec&) = delete;
  ValueSpec& operator=(const ValueSpec&) = delete;

  const std::string& key() const { return key_; }
  const std::string& text() const { return text_; }
  // True when the value is the same number at every cell (no variables, no randomness).
  bool is_constant() const { return constant_; }
  double constant_value() const { return value_; }
  bool uses_time() const { return uses_t_; }
  // True when the value depends on t only (the same number at every cell at a given time).
  bool uniform_in_space() const { return uniform_; }

  // Value at global cell (i, j, k) (cell centre), at time t.
  double at_cell(PetscInt i, PetscInt j, PetscInt k, double t = 0.0);
  // Value at an arbitrary point (x, y, z); (i, j, k) name the cell whose deviates are used.
  double at_point(double x, double y, double z, PetscInt i, PetscInt j, PetscInt k, double t = 0.0);
  // out[c] = at_cell(i0 + c, j, k, t) for c in [0, n), bitwise; cells inside the grid. An
  // expression of muParser's own operators and functions is evaluated a row at a time
  // (fields/column_program.hpp), not cell by cell; a UserError names the first bad cell.
  void fill_row(PetscInt i0, PetscInt n, PetscInt j, PetscInt k, double t, double* out);

private:
  friend struct ValueSpecFunctions;
  double eval_expr();
  double perturbed(double v); // v with this cell's perturbation; a UserError if not finite
  void fill_columns(PetscInt i0, PetscInt n, PetscInt j, PetscInt k, double t);
  void load_strokes(const std::string& expr);
  std::string where() const;

  std::string key_, text_, base_dir_;
  GridSpec grid_;
  std::uint64_t seed_, stream_;
  std::unique_ptr<mu::Parser> parser_;
  bool constant_ = false, uses_t_ = false, uniform_ = false;
  double value_ = 0.0;
  // Setup speed: the expression without its perturbation is one number (evaluated once into
  // base_, the cells add only their deviates), and r/theta are computed only when used.
  bool base_constant_ = false, polar_ = true;
  double base_ = 0.0;
  enum class Perturb { None, Uniform, Gauss } perturb_ = Perturb::None;
  double amount_ = 0.0;
  bool percent_ = false;
  // muParser variables (one array, as ColumnProgram reads them) and the cell being evaluated.
  static constexpr int kVars = 9;
  double var_[kVars] = {};
  double &x_ = var_[0], &y_ = var_[1], &z_ = var_[2], &i_ = var_[3], &j_ = var_[4], &k_ = var_[5],
         &r_ = var_[6], &theta_ = var_[7], &t_ = var_[8];
  std::uint64_t cell_ = 0;
  // Row evaluation: the bytecode (null where the expression has cell-dependent functions), the
  // variables it reads, and the scratch columns (kVars and its stack, cap_ cells each).
  std::unique_ptr<ColumnProgram> row_;
  bool used_[kVars] = {};
  std::vector<double> cols_, stack_;
  size_t cap_ = 0;
  std::map<std::string, io::GreyImage> images_;
  // Stroke fields named in strokes(...) (key "file") and strokes_directed(...) (key "@file").
  std::map<std::string, std::shared_ptr<const StrokeField>> strokes_;
};

} // namespace morphogen
