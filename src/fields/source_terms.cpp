#include "fields/source_terms.hpp"

#include "fields/field_fill.hpp"

#include <cmath>
#include <limits>

namespace morphogen {

SourceTerms::SourceTerms(const Grid& grid, Options& opt, const std::vector<std::string>& species,
                         std::uint64_t seed, const std::string& base_dir)
    : grid_(grid) {
  for (const auto& s : species) {
    const std::string key = "source_" + s;
    auto text = opt.get(key, "source term of " + s + " added to its reaction rate (may use t)");
    if (text) {
      spec_.push_back(std::make_unique<ValueSpec>(key, *text, grid.spec(), seed, base_dir));
      any_ = true;
    } else {
      spec_.emplace_back();
    }
  }
  for (int slot = 0; slot < 2; ++slot) {
    value_[slot].resize(species.size());
    time_[slot].assign(species.size(), std::numeric_limits<double>::quiet_NaN());
  }
}

const double* SourceTerms::at(int s, double t, int slot) {
  if (!spec_[s]) return nullptr;
  auto& v = value_[slot][s];
  const bool fresh = !v.empty() && (time_[slot][s] == t || !spec_[s]->uses_time());
  if (!fresh) {
    v.resize(static_cast<size_t>(grid_.owned().size()));
    const double inf = std::numeric_limits<double>::infinity();
    fill_field(grid_, *spec_[s], v.data(), ArrayLayout::Owned, -inf, inf, t);
    time_[slot][s] = t;
  }
  return v.data();
}

} // namespace morphogen
