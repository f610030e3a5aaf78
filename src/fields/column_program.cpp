// muParser bytecode evaluated over a row (see column_program.hpp). Compiled with
// -ffp-contract=off: bitwise the library's own per-cell Eval().
#include "fields/column_program.hpp"

#include <algorithm>

namespace morphogen {

ColumnProgram::ColumnProgram(const mu::ParserByteCode& bc, const double* vars, int nvars) {
  const mu::SToken* t = bc.GetBase();
  int sidx = 0;
  for (;; ++t) {
    code.push_back(*t);
    var.push_back(-1);
    if (t->Cmd == mu::cmEND) break;
    switch (t->Cmd) {
    case mu::cmLE:
    case mu::cmGE:
    case mu::cmNEQ:
    case mu::cmEQ:
    case mu::cmLT:
    case mu::cmGT:
    case mu::cmADD:
    case mu::cmSUB:
    case mu::cmMUL:
    case mu::cmDIV:
    case mu::cmPOW:
    case mu::cmLAND:
    case mu::cmLOR:
      --sidx;
      break;
    case mu::cmVAL:
      ++sidx;
      break;
    case mu::cmVAR:
    case mu::cmVARPOW2:
    case mu::cmVARPOW3:
    case mu::cmVARPOW4:
    case mu::cmVARMUL: {
      const std::ptrdiff_t v = t->Val.ptr - vars;
      if (v < 0 || v >= nvars) ok = false;
      var.back() = static_cast<int>(v);
      ++sidx;
      break;
    }
    case mu::cmFUNC: {
      const int argc = t->Fun.argc;
      if (argc > 3 || argc < -kMaxArgs) ok = false;
      sidx += argc >= 0 ? 1 - argc : argc + 1; // argc < 0: -argc arguments, one result
      break;
    }
    default:
      ok = false;
    }
    if (!ok) return;
    depth = std::max(depth, sidx);
  }
  ok = sidx == 1; // one result (not a comma-separated list)
}

void ColumnProgram::eval(int n, const double* const* col, double* stack, size_t cap,
                         double* out) const {
  int sidx = 0;
  auto at = [&](int k) { return stack + static_cast<size_t>(k - 1) * cap; };
  for (size_t k = 0;; ++k) {
    const mu::SToken& t = code[k];
    if (t.Cmd == mu::cmEND) break;
    double* __restrict__ a = nullptr;
    const double* __restrict__ b = nullptr;
    if (t.Cmd <= mu::cmLOR) { // binary operators: a = a op b
      --sidx;
      a = at(sidx), b = at(sidx + 1);
    }
    const double* __restrict__ x = var[k] >= 0 ? col[var[k]] : nullptr;
    switch (t.Cmd) {
    case mu::cmLE:
      for (int i = 0; i < n; ++i)
        a[i] = a[i] <= b[i];
      break;
    case mu::cmGE:
      for (int i = 0; i < n; ++i)
        a[i] = a[i] >= b[i];
      break;
    case mu::cmNEQ:
      for (int i = 0; i < n; ++i)
        a[i] = a[i] != b[i];
      break;
    case mu::cmEQ:
      for (int i = 0; i < n; ++i)
        a[i] = a[i] == b[i];
      break;
    case mu::cmLT:
      for (int i = 0; i < n; ++i)
        a[i] = a[i] < b[i];
      break;
    case mu::cmGT:
      for (int i = 0; i < n; ++i)
        a[i] = a[i] > b[i];
      break;
    case mu::cmADD:
      for (int i = 0; i < n; ++i)
        a[i] += b[i];
      break;
    case mu::cmSUB:
      for (int i = 0; i < n; ++i)
        a[i] -= b[i];
      break;
    case mu::cmMUL:
      for (int i = 0; i < n; ++i)
        a[i] *= b[i];
      break;
    case mu::cmDIV:
      for (int i = 0; i < n; ++i)
        a[i] /= b[i];
      break;
    case mu::cmPOW:
      for (int i = 0; i < n; ++i)
        a[i] = mu::MathImpl<double>::Pow(a[i], b[i]);
      break;
    case mu::cmLAND:
      for (int i = 0; i < n; ++i)
        a[i] = a[i] && b[i];
      break;
    case mu::cmLOR:
      for (int i = 0; i < n; ++i)
        a[i] = a[i] || b[i];
      break;
    case mu::cmVAL: {
      double* c = at(++sidx);
      std::fill(c, c + n, t.Val.data2);
      break;
    }
    case mu::cmVAR:
      std::copy(x, x + n, at(++sidx));
      break;
    case mu::cmVARPOW2: {
      double* __restrict__ c = at(++sidx);
      for (int i = 0; i < n; ++i)
        c[i] = x[i] * x[i];
      break;
    }
    case mu::cmVARPOW3: {
      double* __restrict__ c = at(++sidx);
      for (int i = 0; i < n; ++i)
        c[i] = x[i] * x[i] * x[i];
      break;
    }
    case mu::cmVARPOW4: {
      double* __restrict__ c = at(++sidx);
      for (int i = 0; i < n; ++i)
        c[i] = x[i] * x[i] * x[i] * x[i];
      break;
    }
    case mu::cmVARMUL: {
      double* __restrict__ c = at(++sidx);
      const double m = t.Val.data, d = t.Val.data2;
      for (int i = 0; i < n; ++i)
        c[i] = x[i] * m + d;
      break;
    }
    case mu::cmFUNC: {
      const int argc = t.Fun.argc;
      if (argc == 0) {
        double* c = at(++sidx);
        for (int i = 0; i < n; ++i)
          c[i] = t.Fun.cb.call_fun<0>();
      } else if (argc == 1) {
        double* c = at(sidx);
        for (int i = 0; i < n; ++i)
          c[i] = t.Fun.cb.call_fun<1>(c[i]);
      } else if (argc == 2) {
        --sidx;
        double* c = at(sidx);
        const double* c1 = at(sidx + 1);
        for (int i = 0; i < n; ++i)
          c[i] = t.Fun.cb.call_fun<2>(c[i], c1[i]);
      } else if (argc == 3) {
        sidx -= 2;
        double* c = at(sidx);
        const double *c1 = at(sidx + 1), *c2 = at(sidx + 2);
        for (int i = 0; i < n; ++i)
          c[i] = t.Fun.cb.call_fun<3>(c[i], c1[i], c2[i]);
      } else { // -argc arguments (sum, min, max, ...)
        const int m = -argc;
        sidx -= m - 1;
        double args[kMaxArgs];
        double* c = at(sidx);
        for (int i = 0; i < n; ++i) {
          for (int j = 0; j < m; ++j)
            args[j] = at(sidx + j)[i];
          c[i] = t.Fun.cb.call_multfun(args, m);
        }
      }
      break;
    }
    default:
      break; // not reached: the constructor accepts only the tokens above
    }
  }
  std::copy(at(1), at(1) + n, out);
}

} // namespace morphogen
