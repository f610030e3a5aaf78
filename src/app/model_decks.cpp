#include "app/model_decks.hpp"

#include "core/petsc_handle.hpp"

namespace morphogen {

const ModelDeck* model_default_deck(const std::string& model) {
  for (int i = 0; i < kModelDeckCount; ++i)
    if (model == kModelDecks[i].model) return &kModelDecks[i];
  return nullptr;
}

std::string insert_model_default_deck() {
  PetscBool has_model = PETSC_FALSE;
  char model[256] = "";
  MG_PETSC(PetscOptionsGetString(nullptr, nullptr, "-model", model, sizeof model, &has_model));
  PetscBool has_layers = PETSC_FALSE;
  MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-layers", &has_layers));
  if (has_layers) return ""; // coupled layers have their own species names: no default deck
  const ModelDeck* deck = model_default_deck(has_model ? model : "turing");
  if (!deck) return "";
  MG_PETSC(PetscOptionsInsertStringYAML(nullptr, deck->text));
  return deck->name;
}

} // namespace morphogen
