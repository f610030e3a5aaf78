#include "app/deck.hpp"

#include "core/petsc_handle.hpp"
#include "core/user_error.hpp"

#include <filesystem>
#include <fstream>

namespace morphogen {

std::string load_deck(int* argc, char*** argv) {
  std::string deck, base_dir;
  if (*argc > 1 && (*argv)[1][0] != '-') deck = (*argv)[1];
  // A deck anywhere else would be taken by PETSc as an option value or ignored: refuse it.
  for (int i = 2; i < *argc; ++i) {
    const std::string a = (*argv)[i];
    const auto ends = [&](const std::string& e) {
      return a.size() > e.size() && a.compare(a.size() - e.size(), e.size(), e) == 0;
    };
    const std::string prev = (*argv)[i - 1];
    const bool is_value = prev.size() > 1 && prev[0] == '-' && prev != "-options_file" &&
                          prev != "-options_file_yaml";
    if ((ends(".yaml") || ends(".yml")) && !is_value)
      throw UserError("deck " + a +
                      ": the deck must be the first argument (morphogen DECK.yaml "
                      "[-option value ...])");
  }
  if (!deck.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(deck, ec))
      throw UserError("deck " + deck + ": no such file");
    std::ifstream probe(deck);
    if (!probe) throw UserError("deck " + deck + ": cannot be read");
    const std::string err = petsc_quietly([&] {
      return PetscOptionsInsertFileYAML(PETSC_COMM_WORLD, nullptr, deck.c_str(), PETSC_TRUE);
    });
    if (!err.empty()) throw UserError("deck " + deck + ": not a valid YAML deck (" + err + ")");
    base_dir = std::filesystem::path(deck).parent_path().string();
  } else {
    // The default deck is Sanderson Fig. 1: it applies unless an options file is given or a
    // different model is chosen (then the model's own defaults apply).
    PetscBool f1 = PETSC_FALSE, f2 = PETSC_FALSE, has_model = PETSC_FALSE;
    char model[256] = "";
    MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-options_file", &f1));
    MG_PETSC(PetscOptionsHasName(nullptr, nullptr, "-options_file_yaml", &f2));
    MG_PETSC(PetscOptionsGetString(nullptr, nullptr, "-model", model, sizeof model, &has_model));
    const bool other_model = has_model && std::string(model) != "turing";
    if (!f1 && !f2 && !other_model) MG_PETSC(PetscOptionsInsertStringYAML(nullptr, kDefaultDeck));
  }
  // The command line (and any -options_file) overrides the deck.
  MG_PETSC(PetscOptionsInsert(nullptr, argc, argv, nullptr));
  return base_dir;
}

} // namespace morphogen
