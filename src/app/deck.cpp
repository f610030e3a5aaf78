#include "app/deck.hpp"

#include "app/model_decks.hpp"
#include "app/solver_option_check.hpp"
#include "core/options.hpp"
#include "core/petsc_handle.hpp"
#include "core/user_error.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <yaml-cpp/yaml.h>

// GCC 12 warns about yaml-cpp 0.7's node iterators (impl.h) instantiated here: a false positive.
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ >= 12
#pragma GCC diagnostic ignored "-Wdangling-pointer"
#endif

namespace morphogen {

namespace {

bool ends_with(const std::string& a, const std::string& e) {
  return a.size() > e.size() && a.compare(a.size() - e.size(), e.size(), e) == 0;
}

// "name:line:column" of a yaml-cpp mark (0-based there, 1-based here).
std::string at(const std::string& name, const YAML::Mark& m) {
  return name + ":" + std::to_string(m.line + 1) + ":" + std::to_string(m.column + 1);
}

// Line and column (1-based) of byte `pos` in text.
std::string at_offset(const std::string& name, const std::string& text, size_t pos) {
  size_t line = 1, col = 1;
  for (size_t i = 0; i < pos && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return name + ":" + std::to_string(line) + ":" + std::to_string(col);
}

// Walks a mapping; every key must be a plain name, given once (also once after nested keys are
// joined with '_' into option names, which `seen` collects across the whole deck, in lower
// case as PETSc compares them).
std::string check_map(const YAML::Node& map, const std::string& prefix, const std::string& name,
                      std::map<std::string, YAML::Mark>& seen) {
  for (auto it = map.begin(); it != map.end(); ++it) {
    const YAML::Node& key = it->first;
    if (!key.IsScalar() || key.Scalar().empty())
      return at(name, key.Mark()) + ": a key must be a name (key: value)";
    const std::string option = prefix.empty() ? key.Scalar() : prefix + "_" + key.Scalar();
    const YAML::Node& value = it->second;
    if (value.IsMap()) {
      if (const std::string e = check_map(value, option, name, seen); !e.empty()) return e;
      continue;
    }
    // (PETSc's option names ignore case: D_a and d_a are one)
    const auto [prev, fresh] = seen.emplace(lower_case(option), key.Mark());
    if (!fresh)
      return at(name, key.Mark()) + ": duplicate key " + key.Scalar() + " (option -" + option +
             ", already given at line " + std::to_string(prev->second.line + 1) + ")";
  }
  return {};
}

std::string read_file(const std::string& path, const std::string& option) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw UserError(option + path + ": no such file");
  std::ifstream f(path, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  if (!f) throw UserError(option + path + ": cannot be read");
  return ss.str();
}

// Inserts a checked file with PETSc; its refusal (unexpected after the checks) is one line.
void insert_file(const std::string& option, const std::string& path, bool yaml) {
  const std::string err = petsc_quietly([&] {
    return yaml ? PetscOptionsInsertFileYAML(PETSC_COMM_WORLD, nullptr, path.c_str(), PETSC_TRUE)
                : PetscOptionsInsertFile(PETSC_COMM_WORLD, nullptr, path.c_str(), PETSC_TRUE);
  });
  if (!err.empty())
    throw UserError(option + path + ": not a valid " + (yaml ? "YAML deck" : "options file") +
                    " (" + one_line(err) + ")");
}

// A YAML file: checked with yaml-cpp, then inserted. `option` prefixes messages ("deck ",
// "-options_file ").
void insert_yaml(const std::string& option, const std::string& path) {
  const std::string err = check_deck_text(read_file(path, option), path);
  if (!err.empty()) throw UserError(option.substr(0, option.size() - 1) + " " + err);
  insert_file(option, path, true);
}

bool is_yaml_file(const std::string& option, const std::string& path) {
  return option == "options_file_yaml" || ends_with(path, ".yaml") || ends_with(path, ".yml");
}

// (line, option, file) of each -options_file / -options_file_yaml line of a plain options file.
struct NestedFile {
  int line;
  std::string option, path;
};
std::vector<NestedFile> nested_files(const std::string& text) {
  std::vector<NestedFile> out;
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    std::istringstream words(line.substr(0, line.find('#')));
    std::string first, path;
    if ((words >> first) && (first == "-options_file" || first == "-options_file_yaml")) {
      words >> path;
      out.push_back({n, first.substr(1), path});
    }
  }
  return out;
}

// Checks a plain options file and, down its chain, every file its -options_file(_yaml) lines
// name (PETSc inserts those itself, without our checks): a file that is already being read is
// a cycle (PETSc would recurse until the stack overflows), and at most 16 levels are taken.
// `option` prefixes messages ("-options_file ", or the including file's line and option).
void check_options_file_tree(const std::string& option, const std::string& path,
                             std::vector<std::string>& chain) {
  const std::string text = read_file(path, option);
  const std::string head = option.substr(0, option.size() - 1) + " ";
  if (const std::string err = check_options_file_text(text, path); !err.empty())
    throw UserError(head + err);
  std::error_code ec;
  chain.push_back(std::filesystem::weakly_canonical(path, ec).string());
  for (const NestedFile& f : nested_files(text)) {
    const std::string where = head + path + ":" + std::to_string(f.line) + ": -" + f.option;
    if (f.path.empty()) throw UserError(where + ": needs a file name");
    const std::string id = std::filesystem::weakly_canonical(f.path, ec).string();
    if (std::find(chain.begin(), chain.end(), id) != chain.end())
      throw UserError(where + " " + f.path +
                      ": includes a file that is already being read (a cycle)");
    if (chain.size() >= 16)
      throw UserError(where + " " + f.path + ": options files nested more than 16 deep");
    if (!is_yaml_file(f.option, f.path)) {
      check_options_file_tree(where + " ", f.path, chain);
      continue;
    }
    if (const std::string err = check_deck_text(read_file(f.path, where + " "), f.path);
        !err.empty())
      throw UserError(where + " " + err);
  }
  chain.pop_back();
}

// -options_file / -options_file_yaml: YAML when so named or when the file ends in .yaml/.yml
// (as PETSc decides), else PETSc's plain "-option value" format.
void insert_options_file(const OptionsFileArg& f) {
  const std::string option = "-" + f.option + " ";
  if (is_yaml_file(f.option, f.path)) return insert_yaml(option, f.path);
  std::vector<std::string> chain;
  check_options_file_tree(option, f.path, chain);
  insert_file(option, f.path, false);
}

// A deck anywhere but first would be taken by PETSc as an option value or ignored: refuse it.
void refuse_late_deck(int argc, char** argv) {
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    const std::string prev = argv[i - 1];
    const bool is_value = prev.size() > 1 && prev[0] == '-' && prev != "-options_file" &&
                          prev != "-options_file_yaml";
    if ((ends_with(a, ".yaml") || ends_with(a, ".yml")) && !is_value)
      throw UserError("deck " + a +
                      ": the deck must be the first argument (morphogen DECK.yaml "
                      "[-option value ...])");
  }
}

// A word that is neither an option nor an option's value ("-dt 0.1 junk", a value the shell
// split: -init_a 4 + x): PETSc would skip it silently. PETSc's own rule tells names from values.
void refuse_stray_words(int argc, char** argv, int first) {
  const auto is_key = [](const char* a) {
    PetscBool key = PETSC_FALSE;
    MG_PETSC(PetscOptionsValidKey(a, &key));
    return key == PETSC_TRUE;
  };
  std::string last; // the last option with its value, for the message
  for (int i = first; i < argc; ++i) {
    if (is_key(argv[i])) {
      last = argv[i];
      if (i + 1 < argc && !is_key(argv[i + 1])) last += std::string(" ") + argv[++i]; // its value
      continue;
    }
    throw UserError("'" + std::string(argv[i]) + "'" + (last.empty() ? "" : " after " + last) +
                    ": not an option name and not an option's value (options are -name value; "
                    "quote a value that has spaces, e.g. -init_a \"4 + x\")");
  }
}

// PETSc's logging options, read at PetscInitialize from the command line only (PetscFinalize
// then fails on a -log_view that a deck or options file added): name -> value, or nullopt.
using LogOptions = std::vector<std::pair<std::string, std::optional<std::string>>>;
LogOptions log_options() {
  LogOptions out;
  for (const char* name : {"-log_view", "-log_trace", "-log_all", "-log_summary", "-log_exclude"}) {
    const char* value = nullptr;
    PetscBool set = PETSC_FALSE;
    MG_PETSC(PetscOptionsFindPair(nullptr, nullptr, name, &value, &set));
    out.emplace_back(name, set ? std::optional<std::string>(value ? value : "") : std::nullopt);
  }
  return out;
}

// Refuses a logging option that the deck or an options file set or changed, after putting the
// command line's back (so that PetscFinalize does not fail on it).
void refuse_file_log_options(const LogOptions& before) {
  const LogOptions after = log_options();
  for (size_t i = 0; i < before.size(); ++i) {
    if (after[i].second == before[i].second) continue;
    const std::string& name = before[i].first;
    if (before[i].second)
      MG_PETSC(PetscOptionsSetValue(nullptr, name.c_str(), before[i].second->c_str()));
    else
      MG_PETSC(PetscOptionsClearValue(nullptr, name.c_str()));
    throw UserError(name + " " + shown(after[i].second.value_or("")) +
                    " (in the deck or an options file): PETSc reads its logging options from "
                    "the command line only; give " +
                    name + " there");
  }
}

} // namespace

std::string check_deck_text(const std::string& text, const std::string& name) {
  if (const size_t nul = text.find('\0'); nul != std::string::npos)
    return at_offset(name, text, nul) + ": NUL byte (a deck is YAML text)";
  std::vector<YAML::Node> docs;
  try {
    docs = YAML::LoadAll(text);
  } catch (const YAML::Exception& e) {
    return at(name, e.mark) + ": YAML syntax error: " + e.msg;
  }
  if (docs.empty() || (docs.size() == 1 && docs[0].IsNull()))
    return name + ":1:1: empty deck (no keys, only comments or blank lines)";
  if (docs.size() > 1)
    return at(name, docs[1].Mark()) +
           ": a second YAML document (after '---'); a deck is one document";
  if (!docs[0].IsMap())
    return at(name, docs[0].Mark()) + ": a deck is a mapping of keys (key: value)";
  std::map<std::string, YAML::Mark> seen;
  return check_map(docs[0], "", name, seen);
}

std::string check_options_file_text(const std::string& text, const std::string& name) {
  std::istringstream in(text);
  std::string line;
  for (int n = 1; std::getline(in, line); ++n) {
    const std::string where = name + ":" + std::to_string(n);
    if (line.find('\0') != std::string::npos) return where + ": NUL byte (not a text file)";
    std::istringstream words(line.substr(0, line.find('#')));
    std::string first;
    if (!(words >> first)) continue;
    if (first == "alias") continue;
    if (first.size() < 2 || first[0] != '-')
      return where + ": expected -option [value], got '" + first + "'";
  }
  return {};
}

std::string load_deck(int* argc, char*** argv, const std::vector<OptionsFileArg>& files) {
  std::string deck, base_dir;
  const LogOptions logging = log_options();
  if (*argc > 1 && (*argv)[1][0] != '-') deck = (*argv)[1];
  refuse_late_deck(*argc, *argv);
  refuse_stray_words(*argc, *argv, deck.empty() ? 1 : 2);
  if (!deck.empty()) {
    insert_yaml("deck ", deck);
    // Absolute, so that options_used.yaml (which records it as -deck_dir) reruns from anywhere.
    base_dir = std::filesystem::absolute(deck).parent_path().string();
  } else {
    // The default deck of the chosen model (turing: Sanderson Fig. 1), unless an options file
    // is given (app/model_decks.hpp).
    if (files.empty()) insert_model_default_deck();
  }
  for (const auto& f : files)
    insert_options_file(f);
  refuse_file_log_options(logging);
  // The command line overrides the deck and the options files.
  MG_PETSC(PetscOptionsInsert(nullptr, argc, argv, nullptr));
  check_solver_option_values();
  return base_dir;
}

std::string read_deck_dir(Options& opt, const std::string& deck_dir) {
  const std::string dir =
      opt.string("deck_dir", deck_dir,
                 "directory where relative file names in values (png(...), strokes(...)) are "
                 "looked up first, then the working directory (default: the deck's)");
  // (a directory that does not exist here, as in options_used.yaml rerun on another machine,
  // only drops the first place of the lookup; a file is a mistake)
  std::error_code ec;
  if (std::filesystem::exists(dir, ec) && !std::filesystem::is_directory(dir, ec))
    throw UserError("-deck_dir " + shown(dir) + ": not a directory");
  return dir;
}

} // namespace morphogen
