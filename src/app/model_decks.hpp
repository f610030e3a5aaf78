// Per-model default decks: every model forms its pattern from its name alone. `morphogen -model
// NAME` without a deck (and without -options_file) starts from NAME's shipped deck in input/,
// compiled into the binary (the list is MORPHOGEN_MODEL_DECKS in CMakeLists.txt; turing's is
// the embedded default deck input/turing_spots.yaml).
#pragma once

#include <string>

namespace morphogen {

struct ModelDeck {
  const char* model; // registry name
  const char* name;  // the deck's path in the source tree, e.g. input/barkley_spiral.yaml
  const char* text;  // its YAML text
};

extern const ModelDeck kModelDecks[]; // generated from the decks at build time
extern const int kModelDeckCount;

// The default deck of a model, or nullptr for a name that has none (an unknown model: the
// model option's own check reports it).
const ModelDeck* model_default_deck(const std::string& model);

// With no deck and no -options_file: loads the default deck of -model (turing when not given)
// into the options database, below the command line. Returns the deck's name, or "" if none.
std::string insert_model_default_deck();

} // namespace morphogen
