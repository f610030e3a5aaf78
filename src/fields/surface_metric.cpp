#include "fields/surface_metric.hpp"

#include "core/options.hpp"
#include "core/user_error.hpp"

#include <muParser.h>

namespace morphogen {

namespace {

std::string point_text(double u, double v) {
  return "(u, v) = (" + format_double(u) + ", " + format_double(v) + ")";
}

} // namespace

const char* SurfaceMap::option_name(int axis) {
  static const char* names[3] = {"-surface_x", "-surface_y", "-surface_z"};
  return names[axis];
}

SurfaceMap::SurfaceMap(const std::string& x_expr, const std::string& y_expr,
                       const std::string& z_expr, double Lx, double Ly)
    : expr_{x_expr, y_expr, z_expr}, L_{Lx, Ly} {
  for (int a = 0; a < 3; ++a) {
    parser_[a] = std::make_unique<mu::Parser>();
    mu::Parser& P = *parser_[a];
    try {
      P.DefineVar("u", &u_);
      P.DefineVar("v", &v_);
      P.DefineConst("Lx", Lx);
      P.DefineConst("Ly", Ly);
      P.DefineConst("pi", M_PI);
      if (expr_[a].find_first_not_of(" \t") == std::string::npos)
        throw UserError(std::string(option_name(a)) + ": empty expression");
      P.SetExpr(expr_[a]);
      // GetUsedVar parses (syntax errors throw) and lists every name used as a variable, also
      // the undefined ones: refuse those here rather than at the first evaluation.
      for (const auto& [name, ptr] : P.GetUsedVar())
        if (name != "u" && name != "v")
          throw UserError(std::string(option_name(a)) + " " + expr_[a] + ": unknown variable '" +
                          name + "' (allowed: u, v, Lx, Ly, pi)");
      P.Eval(); // binds the variables; any remaining muParser error throws here
    } catch (const mu::Parser::exception_type& e) {
      throw UserError(std::string(option_name(a)) + " " + expr_[a] + ": " + e.GetMsg());
    }
  }
}

SurfaceMap::~SurfaceMap() = default;

double SurfaceMap::eval(int axis) {
  double value;
  try {
    value = parser_[axis]->Eval();
  } catch (const mu::Parser::exception_type& e) {
    throw UserError(std::string(option_name(axis)) + " " + expr_[axis] + ": " + e.GetMsg() +
                    " at " + point_text(u_, v_));
  }
  if (!std::isfinite(value))
    throw UserError(std::string(option_name(axis)) + " " + expr_[axis] + ": evaluates to " +
                    format_double(value) + " at " + point_text(u_, v_));
  return value;
}

void SurfaceMap::position(double u, double v, double X[3]) {
  u_ = u, v_ = v;
  for (int a = 0; a < 3; ++a)
    X[a] = eval(a);
}

void SurfaceMap::jacobian(double u, double v, double J[6]) {
  // Central differences, divided by the distance between the two (rounded) points.
  try {
    for (int d = 0; d < 2; ++d) {
      const double h = 1e-6 * L_[d];
      const double c = d == 0 ? u : v;
      const double plus = c + h, minus = c - h, span = plus - minus;
      double Xp[3], Xm[3];
      position(d == 0 ? plus : u, d == 0 ? v : plus, Xp);
      position(d == 0 ? minus : u, d == 0 ? v : minus, Xm);
      for (int a = 0; a < 3; ++a)
        J[3 * d + a] = (Xp[a] - Xm[a]) / span;
    }
  } catch (const UserError&) {
    double X[3];
    position(u, v, X); // an error at (u, v) itself names that point
    throw;             // else the one at the neighbouring point
  }
  double scaled[6];
  for (int k = 0; k < 6; ++k)
    scaled[k] = J[k] * L_[k / 3];
  if (surface_map_degenerate(scaled)) {
    double M[3];
    const double det = surface_metric(J, M);
    throw UserError("surface map (" + std::string(option_name(0)) + " " + expr_[0] + ", " +
                    option_name(1) + " " + expr_[1] + ", " + option_name(2) + " " + expr_[2] +
                    ") is degenerate at " + point_text(u, v) +
                    ": dX/du and dX/dv are zero or parallel (|dX/du|^2 = " + format_double(M[0]) +
                    ", |dX/dv|^2 = " + format_double(M[2]) + ", det M = " + format_double(det) +
                    ")");
  }
}

void SurfaceMap::corrected_tensor(double u, double v, const double sigma_surface[3],
                                  double sigma_param[3]) {
  double J[6];
  jacobian(u, v, J);
  surface_corrected_tensor(J, sigma_surface, sigma_param);
}

} // namespace morphogen
