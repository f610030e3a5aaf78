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

#include <functional>
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
  // True with -help in the options database (PETSc's help, `-help petsc`) or after
  // request_help() (morphogen's own `-help`, which PETSc never sees). Either way the options are
  // not printed as they are read: the caller prints records() grouped at the end.
  bool help_requested() const { return help_; }
  // Process-wide: every Options constructed afterwards reports help_requested().
  static void request_help() { help_everywhere_ = true; }

  // A hint for an unknown option (e.g. "F is a parameter of gray_scott"), or "" for none; used
  // by check_unused before the "did you mean" suggestion.
  void set_unknown_hint(std::function<std::string(const std::string& name)> hint) {
    hint_ = std::move(hint);
  }

  // Throw UserError for the first option set by the user that nothing read; with a prefix, only
  // options whose names start with it are considered (a program's own options, checked before
  // the objects that read the rest exist).
  void check_unused(const std::string& prefix = "") const;

  // Options that were read, as a flat YAML deck (key: "value").
  std::string to_yaml(const std::string& header) const;

  static double parse_real(const std::string& name, const std::string& text);
  // (lo, hi: the range an integer beyond PetscInt's is refused with; default PetscInt's own)
  static PetscInt parse_int(const std::string& name, const std::string& text,
                            PetscInt lo = std::numeric_limits<PetscInt>::min(),
                            PetscInt hi = std::numeric_limits<PetscInt>::max());

private:
  void record(const std::string& name, const std::string& value, const std::string& help);
  inline static bool help_everywhere_ = false;
  MPI_Comm comm_;
  bool help_ = false;
  std::function<std::string(const std::string&)> hint_;
  std::vector<Record> records_;
  std::vector<std::string> known_;
};

// Levenshtein distance (for "did you mean").
size_t edit_distance(const std::string& a, const std::string& b);

// Shortest text that reads back as exactly v (20, 0.0078125, 1e-12): for files
// (options_used.yaml, indexes), where full precision matters.
std::string format_double(double v);

// v for people, in messages: at most 6 significant digits, no trailing zeros
// (11249.999999999998 -> 11250, 1.7976931348623157e+308 -> 1.79769e+308).
std::string format_number(double v);

// The allowed range [lo, hi] for messages and help: "allowed [0, 1]", "allowed >= 0" when hi is
// +inf or the largest double, "allowed <= 1" when lo is -inf or the lowest double, "any number".
std::string allowed_range(double lo, double hi);

// Every (name without '-', value) in the PETSc options database, read as text (no option is
// marked used); a name followed by no value has "".
std::vector<std::pair<std::string, std::string>> all_petsc_options();

// PETSc's refusal `petsc_message` of an option under `prefix` (e.g. "diffusion_"), said as
// "-diffusion_ksp_rtol abc: not a number (PETSc: ...)": the option is the one whose value the
// message quotes. "" when no option under prefix matches.
std::string name_petsc_option_error(const std::string& prefix, const std::string& petsc_message);

// Each line break (and any run of whitespace around it) in text replaced by one space: a
// PETSc message made fit for a one-line error.
std::string one_line(const std::string& text);

// text in lower case (ASCII), as PETSc compares option names and flag values.
std::string lower_case(std::string text);

// A value as a message shows it: as is, or in double quotes when it is empty or has white
// space or control characters at all (-steps " ", -integrator "ts "), which would not show.
std::string shown(const std::string& value);

} // namespace morphogen
