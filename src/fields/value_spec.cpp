#include "fields/value_spec.hpp"

#include "core/hash_rng.hpp"
#include "core/options.hpp"
#include "core/user_error.hpp"
#include "fields/column_program.hpp"
#include "fields/strokes_field.hpp"

#include <cmath>
#include <muParser.h>
#include <regex>

namespace morphogen {

namespace {

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t"), e = s.find_last_not_of(" \t");
  return b == std::string::npos ? std::string() : s.substr(b, e - b + 1);
}

// Position of a top-level "+-" (outside parentheses and quotes), or npos.
size_t find_plus_minus(const std::string& s) {
  int depth = 0;
  bool quoted = false;
  for (size_t p = 0; p + 1 < s.size(); ++p) {
    const char c = s[p];
    if (c == '"') quoted = !quoted;
    if (quoted) continue;
    if (c == '(') ++depth;
    if (c == ')') --depth;
    if (depth == 0 && c == '+' && s[p + 1] == '-') return p;
  }
  return std::string::npos;
}

} // namespace

std::string resolve_path(const std::string& base_dir, const std::string& file) {
  if (base_dir.empty() || file.empty() || file[0] == '/') return file;
  const std::string alt = base_dir + "/" + file;
  if (FILE* f = std::fopen(alt.c_str(), "rb")) {
    std::fclose(f);
    return alt;
  }
  return file;
}

namespace {

// Cell index of coordinate x along axis d: wrapped (periodic) or clamped to the grid.
int cell_of(double x, const GridSpec& g, int d) {
  const long n = static_cast<long>(g.n[d]);
  long c = static_cast<long>(std::floor(x / g.h(d)));
  if (g.bc[d] == Boundary::Periodic) return static_cast<int>(((c % n) + n) % n);
  return static_cast<int>(c < 0 ? 0 : (c >= n ? n - 1 : c));
}

double periodic_delta(double d, double L, bool periodic) {
  if (!periodic) return d;
  d = std::fmod(d, L);
  if (d > 0.5 * L) d -= L;
  if (d < -0.5 * L) d += L;
  return d;
}

} // namespace

namespace {

// spots(n, radius, seed): n an integer in [0, kMaxSpots] (each cell tests every spot, so n
// bounds the cost: 1e5 spots on 256^2 cells is ~1e10 tests), radius finite, seed an integer in
// [0, 2^53]. A mu::ParserError, reported with the key and the cell by eval_expr.
void check_spots_args(double n, double radius, double seed) {
  constexpr double kSeedMax = 9007199254740992.0; // 2^53: every integer exact
  if (!(n >= 0 && n <= kMaxSpots && n == std::floor(n)))
    throw mu::ParserError("spots(n, radius, seed): n = " + format_number(n) +
                          ", allowed an integer in [0, " + std::to_string(kMaxSpots) + "]");
  if (!std::isfinite(radius))
    throw mu::ParserError("spots(n, radius, seed): radius = " + format_number(radius) +
                          ", allowed a finite number");
  if (!(seed >= 0 && seed <= kSeedMax && seed == std::floor(seed)))
    throw mu::ParserError("spots(n, radius, seed): seed = " + format_number(seed) +
                          ", allowed an integer in [0, 2^53]");
}

} // namespace

// A top-level '=' (an assignment: muParser would assign to x) or ',' (a list: muParser would
// evaluate every item and keep the last) in an expression: "" if none, else the message.
std::string top_level_problem(const std::string& expr) {
  int depth = 0;
  bool quoted = false;
  for (size_t p = 0; p < expr.size(); ++p) {
    const char c = expr[p];
    if (c == '"') quoted = !quoted;
    if (quoted) continue;
    depth += c == '(' ? 1 : c == ')' ? -1 : 0;
    const char prev = p > 0 ? expr[p - 1] : ' ', next = p + 1 < expr.size() ? expr[p + 1] : ' ';
    if (c == '=' && prev != '=' && prev != '<' && prev != '>' && prev != '!' && next != '=')
      return "'=' is an assignment, allowed: one expression (compare with ==)";
    if (c == ',' && depth == 0)
      return "a comma-separated list, allowed: one expression (commas only between a "
             "function's arguments)";
  }
  return {};
}

// Polar radius and angle about the domain centre (one out-of-line function, so that the cell
// and row evaluations round alike).
[[gnu::noinline]] void polar_of(double x, double y, const GridSpec& g, double* r, double* theta) {
  const double cx = x - 0.5 * g.L[0], cy = y - 0.5 * g.L[1];
  *r = std::sqrt(cx * cx + cy * cy);
  *theta = std::atan2(cy, cx);
}

// muParser callbacks (user data = the ValueSpec being evaluated).
struct ValueSpecFunctions {
  static ValueSpec& vs(void* p) { return *static_cast<ValueSpec*>(p); }
  static double dx(ValueSpec& v, int d, double c) {
    const double pos = d == 0 ? v.x_ : d == 1 ? v.y_ : v.z_;
    return periodic_delta(pos - c, v.grid_.L[d], v.grid_.bc[d] == Boundary::Periodic);
  }
  static double square(void* p, double cx, double cy, double half) {
    auto& v = vs(p);
    return std::abs(dx(v, 0, cx)) <= half && std::abs(dx(v, 1, cy)) <= half ? 1.0 : 0.0;
  }
  static double disk(void* p, double cx, double cy, double radius) {
    auto& v = vs(p);
    const double a = dx(v, 0, cx), b = dx(v, 1, cy);
    return a * a + b * b <= radius * radius ? 1.0 : 0.0;
  }
  static double ball(void* p, double cx, double cy, double cz, double radius) {
    auto& v = vs(p);
    const double a = dx(v, 0, cx), b = dx(v, 1, cy), c = dx(v, 2, cz);
    return a * a + b * b + c * c <= radius * radius ? 1.0 : 0.0;
  }
  static double spots(void* p, double n, double radius, double seed) {
    auto& v = vs(p);
    check_spots_args(n, radius, seed);
    const auto s = static_cast<std::uint64_t>(seed);
    const std::uint64_t stream = rng::stream_id("spots");
    const long count = static_cast<long>(n);
    for (long m = 0; m < count; ++m) {
      double d2 = 0;
      for (int d = 0; d < v.grid_.dim; ++d) {
        const double c =
            rng::uniform(s, stream, static_cast<std::uint64_t>(3 * m + d)) * v.grid_.L[d];
        const double e = dx(v, d, c);
        d2 += e * e;
      }
      if (d2 <= radius * radius) return 1.0;
    }
    return 0.0;
  }
  static double noise(void* p) {
    auto& v = vs(p);
    return rng::uniform(v.seed_, v.stream_ ^ 0x6e6f697365ULL, v.cell_);
  }
  static double gnoise(void* p) {
    auto& v = vs(p);
    return rng::gaussian(v.seed_, v.stream_ ^ 0x676e6f697365ULL, v.cell_);
  }
  static double png(void* p, const char* file, double lo, double hi) {
    auto& v = vs(p);
    const auto it = v.images_.find(file);
    if (it == v.images_.end()) return std::nan("");
    const double u = v.x_ / v.grid_.L[0], w = v.y_ / v.grid_.L[1];
    return lo + (hi - lo) * io::sample_bilinear(it->second, u, w);
  }
  static double stroke_value(void* p, const std::string& key, bool distance) {
    auto& v = vs(p);
    const auto it = v.strokes_.find(key);
    if (it == v.strokes_.end()) return std::nan("");
    const int i = cell_of(v.x_, v.grid_, 0), j = cell_of(v.y_, v.grid_, 1);
    return distance ? it->second->distance_at(i, j) : it->second->theta_at(i, j);
  }
  static double strokes(void* p, const char* file) { return stroke_value(p, file, false); }
  static double strokes_directed(void* p, const char* file) {
    return stroke_value(p, std::string("@") + file, false);
  }
  static double strokes_distance(void* p, const char* file) { return stroke_value(p, file, true); }
};

ValueSpec::ValueSpec(const std::string& key, const std::string& text, const GridSpec& grid,
                     std::uint64_t seed, const std::string& base_dir)
    : key_(key), text_(text), base_dir_(base_dir), grid_(grid), seed_(seed),
      stream_(rng::stream_id(key)), parser_(std::make_unique<mu::Parser>()) {
  std::string expr = text;
  if (const size_t pm = find_plus_minus(text); pm != std::string::npos) {
    expr = text.substr(0, pm);
    static const std::regex amount_re(
        R"(^\s*([0-9.eE+\-]+)\s*(%?)\s*(uniform|gauss|gaussian)?\s*$)");
    std::smatch m;
    const std::string rest = text.substr(pm + 2);
    if (!std::regex_match(rest, m, amount_re))
      throw UserError("-" + key + " " + text +
                      ": bad perturbation after '+-', expected AMOUNT[%] [uniform|gauss]");
    amount_ = Options::parse_real(key, m[1].str());
    if (amount_ < 0) throw UserError("-" + key + " " + text + ": perturbation amount must be >= 0");
    percent_ = !m[2].str().empty();
    perturb_ = m[3].matched && m[3].str() != "uniform" ? Perturb::Gauss : Perturb::Uniform;
  }
  expr = trim(expr);
  if (expr.empty()) throw UserError("-" + key + ": empty value");
  if (const std::string bad = top_level_problem(expr); !bad.empty())
    throw UserError("-" + key + " " + text + ": " + bad);

  // Images named in png("...") are loaded once, up front, so a missing file fails at setup.
  static const std::regex png_re(R"(png\s*\(\s*"([^"]*)\")");
  for (std::sregex_iterator it(expr.begin(), expr.end(), png_re), end; it != end; ++it) {
    const std::string file = (*it)[1].str();
    try {
      images_.emplace(file, io::read_png_grey(resolve_path(base_dir_, file)));
    } catch (const UserError& e) {
      throw UserError("-" + key + " " + text + ": " + e.what());
    }
  }
  load_strokes(expr);

  mu::Parser& P = *parser_;
  try {
    P.DefineVar("x", &x_);
    P.DefineVar("y", &y_);
    P.DefineVar("z", &z_);
    P.DefineVar("i", &i_);
    P.DefineVar("j", &j_);
    P.DefineVar("k", &k_);
    P.DefineVar("r", &r_);
    P.DefineVar("theta", &theta_);
    P.DefineVar("t", &t_);
    const char* L[3] = {"Lx", "Ly", "Lz"};
    const char* N[3] = {"nx", "ny", "nz"};
    const char* H[3] = {"hx", "hy", "hz"};
    for (int d = 0; d < 3; ++d) {
      P.DefineConst(L[d], grid.L[d]);
      P.DefineConst(N[d], static_cast<double>(grid.n[d]));
      P.DefineConst(H[d], grid.h(d));
    }
    P.DefineConst("pi", M_PI);
    P.DefineFunUserData("square", &ValueSpecFunctions::square, this, false);
    P.DefineFunUserData("disk", &ValueSpecFunctions::disk, this, false);
    P.DefineFunUserData("ball", &ValueSpecFunctions::ball, this, false);
    P.DefineFunUserData("spots", &ValueSpecFunctions::spots, this, false);
    P.DefineFunUserData("noise", &ValueSpecFunctions::noise, this, false);
    P.DefineFunUserData("gnoise", &ValueSpecFunctions::gnoise, this, false);
    P.DefineFunUserData("png", &ValueSpecFunctions::png, this, false);
    P.DefineFunUserData("strokes", &ValueSpecFunctions::strokes, this, false);
    P.DefineFunUserData("strokes_directed", &ValueSpecFunctions::strokes_directed, this, false);
    P.DefineFunUserData("strokes_distance", &ValueSpecFunctions::strokes_distance, this, false);
    P.SetExpr(expr);
    const auto& used = P.GetUsedVar(); // parses; throws on syntax errors
    uses_t_ = used.count("t") > 0;
    static const std::regex cellwise(
        R"(\b(square|disk|ball|spots|noise|gnoise|png|strokes\w*)\s*\()");
    const bool cell_funcs = std::regex_search(expr, cellwise);
    uniform_ =
        (used.empty() || (used.size() == 1 && uses_t_)) && !cell_funcs && perturb_ == Perturb::None;
    polar_ = used.count("r") > 0 || used.count("theta") > 0;
    base_constant_ = used.empty() && !cell_funcs;
    if (!cell_funcs && !base_constant_ && mu::ParserVersion.rfind("2.3.", 0) == 0) {
      P.Eval(); // compiles the bytecode
      row_ = std::make_unique<ColumnProgram>(P.GetByteCode(), var_, kVars);
      if (!row_->ok) row_.reset();
      const char* names[kVars] = {"x", "y", "z", "i", "j", "k", "r", "theta", "t"};
      for (int v = 0; v < kVars; ++v)
        used_[v] = used.count(names[v]) > 0;
    }
    if (base_constant_) base_ = P.Eval(); // the same number Eval() gives at every cell
    if (used.empty() && !cell_funcs && perturb_ == Perturb::None) {
      constant_ = true;
      value_ = P.Eval();
      if (!std::isfinite(value_))
        throw UserError("-" + key + " " + text + ": evaluates to " + format_double(value_));
    }
  } catch (const mu::Parser::exception_type& e) {
    throw UserError("-" + key + " " + text + ": " + e.GetMsg());
  }
}

ValueSpec::~ValueSpec() = default;

// Stroke files named in strokes("..."), strokes_directed("...") and strokes_distance("...") are
// read and their fields computed (or found in the cache) up front: a bad file fails at setup.
void ValueSpec::load_strokes(const std::string& expr) {
  static const std::regex re(R"(\b(strokes|strokes_directed|strokes_distance)\s*\(\s*"([^"]*)\")");
  for (std::sregex_iterator it(expr.begin(), expr.end(), re), end; it != end; ++it) {
    const bool directed = (*it)[1].str() == "strokes_directed";
    const std::string file = (*it)[2].str(), mapkey = (directed ? "@" : "") + file;
    if (strokes_.count(mapkey)) continue;
    if (static_cast<long>(grid_.n[0]) * static_cast<long>(grid_.n[1]) > kMaxStrokeCells)
      throw UserError("-" + key_ + " " + text_ + ": stroke fields are computed whole on every " +
                      "rank; grid " + std::to_string(grid_.n[0]) + " x " +
                      std::to_string(grid_.n[1]) + " is over the limit of 4096^2 cells in x-y");
    const int nx = static_cast<int>(grid_.n[0]), ny = static_cast<int>(grid_.n[1]);
    const bool px = grid_.bc[0] == Boundary::Periodic, py = grid_.bc[1] == Boundary::Periodic;
    const FmmGrid g{nx, ny, grid_.h(0), grid_.h(1), px, py};
    try {
      strokes_.emplace(mapkey,
                       cached_stroke_field(resolve_path(base_dir_, file), g,
                                           directed ? StrokeAngle::Directed : StrokeAngle::Axial));
    } catch (const UserError& e) {
      throw UserError("-" + key_ + " " + text_ + ": " + e.what());
    }
  }
}

std::string ValueSpec::where() const {
  return " at cell (" + std::to_string(static_cast<long>(i_)) + "," +
         std::to_string(static_cast<long>(j_)) + "," + std::to_string(static_cast<long>(k_)) + ")";
}

double ValueSpec::eval_expr() {
  double v;
  try {
    v = base_constant_ ? base_ : parser_->Eval();
  } catch (const mu::Parser::exception_type& e) {
    throw UserError("-" + key_ + " " + text_ + ": " + e.GetMsg() + where());
  }
  return perturbed(v);
}

double ValueSpec::perturbed(double v) {
  if (perturb_ != Perturb::None) {
    const double a = percent_ ? amount_ * 0.01 * std::abs(v) : amount_;
    v += perturb_ == Perturb::Uniform ? a * (2.0 * rng::uniform(seed_, stream_, cell_) - 1.0)
                                      : a * rng::gaussian(seed_, stream_, cell_);
  }
  if (!std::isfinite(v))
    throw UserError("-" + key_ + " " + text_ + ": evaluates to " + format_double(v) + where());
  return v;
}

double ValueSpec::at_point(double x, double y, double z, PetscInt i, PetscInt j, PetscInt k,
                           double t) {
  if (constant_) return value_;
  x_ = x, y_ = y, z_ = z, t_ = t;
  i_ = static_cast<double>(i), j_ = static_cast<double>(j), k_ = static_cast<double>(k);
  if (polar_) polar_of(x, y, grid_, &r_, &theta_);
  const auto wrap = [&](PetscInt c, int d) {
    return c >= 0 && c < grid_.n[d] ? c : ((c % grid_.n[d]) + grid_.n[d]) % grid_.n[d];
  };
  cell_ = static_cast<std::uint64_t>(wrap(i, 0)) +
          static_cast<std::uint64_t>(grid_.n[0]) *
              (static_cast<std::uint64_t>(wrap(j, 1)) +
               static_cast<std::uint64_t>(grid_.n[1]) * static_cast<std::uint64_t>(wrap(k, 2)));
  return eval_expr();
}

double ValueSpec::at_cell(PetscInt i, PetscInt j, PetscInt k, double t) {
  const double x = (static_cast<double>(i) + 0.5) * grid_.h(0);
  const double y = (static_cast<double>(j) + 0.5) * grid_.h(1);
  const double z = grid_.dim == 3 ? (static_cast<double>(k) + 0.5) * grid_.h(2) : 0.0;
  return at_point(x, y, z, i, j, k, t);
}

// The variables' columns of cells [i0, i0 + n) of row (j, k) at time t (only those read).
void ValueSpec::fill_columns(PetscInt i0, PetscInt n, PetscInt j, PetscInt k, double t) {
  const double y = (static_cast<double>(j) + 0.5) * grid_.h(1);
  const double z = grid_.dim == 3 ? (static_cast<double>(k) + 0.5) * grid_.h(2) : 0.0;
  const double fixed[kVars] = {0, y, z, 0, static_cast<double>(j), static_cast<double>(k), 0, 0, t};
  const bool polar = used_[6] || used_[7];
  for (int v = 0; v < kVars; ++v) {
    double* c = cols_.data() + static_cast<size_t>(v) * cap_;
    if (!used_[v] && !(v == 0 && polar)) continue;
    for (PetscInt q = 0; q < n; ++q) {
      const double i = static_cast<double>(i0 + q);
      c[q] = v == 0 ? (i + 0.5) * grid_.h(0) : v == 3 ? i : fixed[v];
    }
  }
  if (polar)
    for (PetscInt q = 0; q < n; ++q)
      polar_of(cols_[static_cast<size_t>(q)], y, grid_, &cols_[6 * cap_ + static_cast<size_t>(q)],
               &cols_[7 * cap_ + static_cast<size_t>(q)]);
}

void ValueSpec::fill_row(PetscInt i0, PetscInt n, PetscInt j, PetscInt k, double t, double* out) {
  if (constant_) {
    std::fill(out, out + n, value_);
    return;
  }
  if (!row_ && !base_constant_) {
    for (PetscInt q = 0; q < n; ++q)
      out[q] = at_cell(i0 + q, j, k, t);
    return;
  }
  if (base_constant_) { // a number and a perturbation: no variables to set
    std::fill(out, out + n, base_);
  } else {
    if (static_cast<size_t>(n) > cap_) {
      cap_ = static_cast<size_t>(n);
      cols_.assign(kVars * cap_, 0.0);
      stack_.assign(static_cast<size_t>(row_->depth) * cap_, 0.0);
    }
    fill_columns(i0, n, j, k, t);
    const double* col[kVars];
    for (int v = 0; v < kVars; ++v)
      col[v] = cols_.data() + static_cast<size_t>(v) * cap_;
    row_->eval(static_cast<int>(n), col, stack_.data(), cap_, out);
  }
  const std::uint64_t first =
      static_cast<std::uint64_t>(i0) +
      static_cast<std::uint64_t>(grid_.n[0]) *
          (static_cast<std::uint64_t>(j) +
           static_cast<std::uint64_t>(grid_.n[1]) * static_cast<std::uint64_t>(k));
  j_ = static_cast<double>(j), k_ = static_cast<double>(k);
  for (PetscInt q = 0; q < n; ++q) {
    cell_ = first + static_cast<std::uint64_t>(q);
    i_ = static_cast<double>(i0 + q);
    out[q] = perturbed(out[q]);
  }
}

} // namespace morphogen
