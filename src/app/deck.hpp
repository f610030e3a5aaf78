// Decks: YAML files loaded into PETSc's options database (nested keys become prefixed options,
// lists become comma-separated values). Precedence, lowest first: the deck (or, with no deck,
// no -options_file and no -model other than turing, the embedded default deck
// input/turing_spots.yaml), then the command line. Returns the directory of the deck (for relative
// file names inside it), or "".
#pragma once

#include <string>

namespace morphogen {

extern const char* const kDefaultDeck; // input/turing_spots.yaml, embedded at build time
extern const char* const kDefaultDeckName;

// argv[1], if it does not start with '-', is the deck path.
std::string load_deck(int* argc, char*** argv);

} // namespace morphogen
