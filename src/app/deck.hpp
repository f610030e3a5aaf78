// Decks: YAML files loaded into PETSc's options database (nested keys become prefixed options,
// lists become comma-separated values). Precedence, lowest first: the deck (or, with no deck
// and no -options_file, the embedded default deck of -model, app/model_decks.hpp: for turing
// input/turing_spots.yaml), then each -options_file in the order given, then the command line.
//
// Every deck and YAML options file is first checked with a real YAML parser (yaml-cpp): a
// syntax error, a duplicate key (also after nesting is flattened: grid: {n: ..} and grid_n),
// a second YAML document, a NUL byte, or an empty (or comments-only) file is a UserError
// "file:line:column: what" before anything is inserted. Values of any length are kept whole.
#pragma once

#include "core/options.hpp"

#include <string>
#include <vector>

namespace morphogen {

extern const char* const kDefaultDeck; // input/turing_spots.yaml, embedded at build time
extern const char* const kDefaultDeckName;

// "" when `text` is a usable YAML deck, else "name:line:column: what" (the first problem; line
// and column count from 1). Pure: no PETSc, no MPI.
std::string check_deck_text(const std::string& text, const std::string& name);

// "" when the plain PETSc options file `text` is usable (each line: "-option [value]", "alias
// -a -b" or a # comment), else "name:line: what". Pure.
std::string check_options_file_text(const std::string& text, const std::string& name);

// An options file given on the command line, taken off argv before PetscInitialize (so that
// PETSc never fails on it with a trace): `option` is "options_file" or "options_file_yaml".
struct OptionsFileArg {
  std::string option, path;
};

// Collective (PETSC_COMM_WORLD). argv[1], if it does not start with '-', is the deck path.
// Loads the deck (or the default), then `files`, then argv. Returns the directory of the deck
// (for relative file names inside it), or "". UserError on any problem with the deck or a file.
std::string load_deck(int* argc, char*** argv, const std::vector<OptionsFileArg>& files = {});

// -deck_dir: where relative file names in values (png(...), strokes(...)) are looked up first;
// its default is the deck's directory from load_deck, so options_used.yaml records it and a
// rerun from the output directory finds the same files.
std::string read_deck_dir(Options& opt, const std::string& deck_dir);

} // namespace morphogen
