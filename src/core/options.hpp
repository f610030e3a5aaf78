// The one options database: typed, range-checked reads from PETSc's options, each recorded
// with its help text and resolved value.
//
// Every module reads its options through this class, so that
//  - `-help` lists every option the chosen configuration reads (name, default, range, help);
//  - the resolved values can be written to options_used.yaml (a deck that reproduces the run);
//  - after setup, an option that nothing read is an error with a "did you mean" suggestion;
//  - a bad value is a UserError naming the option, the value and what is allowed.
// Option names are given without the leading dash.
#pragma once

#include <petscsys.h>

#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace morphogen {

class Options {
public:
  struct Record {
    std::string name, value, help;
  };

  static constexpr double inf = std::numeric_limits<double>::infinity();

  explicit Options(MPI_Comm comm);

  double real(const std::string& name, double def, double lo, double hi, const std::string& help);
  PetscInt integer(const std::string& name, PetscInt def, PetscInt lo, PetscInt hi,
                   const std::string& help);
  bool flag(const std::string& name, bool def, const std::string& help);
  std::string string(const std::string& name, const std::string& def, const std::string& help);
  std::string choice(const std::string& name, const std::string& def,
                     const std::vector<std::string>& allowed, const std::string& help);
  // Comma-separated list; `count` values allowed (a single value is broadcast to all when
  // broadcast_single is true).
  std::vector<std::string> list(const std::string& name, const std::vector<std::string>& def,
                                size_t min_count, size_t max_count, const std::string& help);
  // Raw string if set (recorded as read); nullopt otherwise.
  std::optional<std::string> get(const std::string& name, const std::string& help);
  bool is_set(const std::string& name) const;

  // Record an option that another layer (a PETSc object) reads later: it is not reported as
  // unused, and "did you mean" knows it.
  void known(const std::string& name) { known_.push_back(name); }

  const std::vector<Record>& records() const { return records_; }
  bool help_requested() const { return help_; }

  // Throw UserError for the first option set by the user that nothing read.
  void check_unused() const;

  // Options that were read, as a flat YAML deck (key: "value").
  std::string to_yaml(const std::string& header) const;

  static double parse_real(const std::string& name, const std::string& text);
  static PetscInt parse_int(const std::string& name, const std::string& text);

private:
  void record(const std::string& name, const std::string& value, const std::string& help);
  MPI_Comm comm_;
  bool help_ = false;
  std::vector<Record> records_;
  std::vector<std::string> known_;
};

// Levenshtein distance (for "did you mean").
size_t edit_distance(const std::string& a, const std::string& b);

std::string format_double(double v);

} // namespace morphogen
