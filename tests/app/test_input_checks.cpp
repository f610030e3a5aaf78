// Input validation without PETSc: deck and options-file checks (app/deck.hpp), the command-line
// pre-scan (app/command_line.hpp), directory-name checks (app/path_check.hpp) and the number
// formatting of messages (core/options.hpp).
#include "app/command_line.hpp"
#include "app/deck.hpp"
#include "app/path_check.hpp"
#include "core/options.hpp"

#include <filesystem>
#include <fstream>
#include <gtest/gtest.h>
#include <sstream>

using namespace morphogen;

namespace {

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  std::stringstream ss;
  ss << f.rdbuf();
  return ss.str();
}

} // namespace

TEST(DeckCheck, EveryShippedDeckIsValid) {
  const auto input = std::filesystem::path(__FILE__).parent_path() / "../../input";
  int n = 0;
  for (const auto& e : std::filesystem::directory_iterator(input)) {
    if (e.path().extension() != ".yaml") continue;
    EXPECT_EQ(check_deck_text(slurp(e.path()), e.path().filename().string()), "") << e.path();
    ++n;
  }
  EXPECT_GT(n, 20);
}

TEST(DeckCheck, SyntaxErrorHasLineAndColumn) {
  const std::string e = check_deck_text("model: turing\ngrid: [unclosed\n", "d.yaml");
  EXPECT_EQ(e.rfind("d.yaml:", 0), 0u) << e;
  EXPECT_NE(e.find("d.yaml:3:1: "), std::string::npos) << e;
}

TEST(DeckCheck, DuplicateKeys) {
  EXPECT_EQ(check_deck_text("steps: 10\nsteps: 20\n", "d.yaml"),
            "d.yaml:2:1: duplicate key steps (option -steps, already given at line 1)");
  const std::string nested = check_deck_text("grid:\n  n: 32,32\n  n: 16,16\n", "d.yaml");
  EXPECT_NE(nested.find("d.yaml:3:3: duplicate key n (option -grid_n"), std::string::npos)
      << nested;
  const std::string flat = check_deck_text("grid:\n  n: 32,32\ngrid_n: 16,16\n", "d.yaml");
  EXPECT_NE(flat.find("d.yaml:3:1: duplicate key grid_n (option -grid_n, already given at line 2"),
            std::string::npos)
      << flat;
}

TEST(DeckCheck, SecondDocumentNulEmpty) {
  EXPECT_NE(check_deck_text("steps: 1\n---\nsteps: 2\n", "d.yaml").find("second YAML document"),
            std::string::npos);
  EXPECT_EQ(check_deck_text(std::string("steps: 1\nmo\0del: x\n", 20), "d.yaml"),
            "d.yaml:2:3: NUL byte (a deck is YAML text)");
  EXPECT_NE(check_deck_text("", "d.yaml").find("d.yaml:1:1: empty deck"), std::string::npos);
  EXPECT_NE(check_deck_text("# only\n  # comments\n\n", "d.yaml").find("empty deck"),
            std::string::npos);
  EXPECT_NE(check_deck_text("just a string\n", "d.yaml").find("a deck is a mapping"),
            std::string::npos);
}

TEST(DeckCheck, LongValuesAndListsAreFine) {
  EXPECT_EQ(check_deck_text("init:\n  a: \"4" + std::string(6000, ' ') + "\"\n", "d.yaml"), "");
  EXPECT_EQ(check_deck_text("grid:\n  n: [256, 256]\nD: {a: 0.1, b: 0.2}\n", "d.yaml"), "");
}

TEST(OptionsFileCheck, Lines) {
  EXPECT_EQ(check_options_file_text("# c\n-steps 10\n\n-force_dt\nalias -a -b\n", "f"), "");
  EXPECT_EQ(check_options_file_text("-steps 10\nsteps 20\n", "f"),
            "f:2: expected -option [value], got 'steps'");
}

TEST(CommandLine, TakesHelpVersionAndOptionsFiles) {
  std::vector<std::string> words = {"morphogen", "deck.yaml",     "-h",   "-steps", "5",
                                    "--version", "-options_file", "o.txt"};
  std::vector<char*> argv;
  for (auto& w : words)
    argv.push_back(w.data());
  argv.push_back(nullptr);
  int argc = static_cast<int>(words.size());
  const CommandLine cl = take_command_line(&argc, argv.data());
  EXPECT_EQ(cl.help, CommandLine::Help::Morphogen);
  EXPECT_TRUE(cl.version);
  ASSERT_EQ(cl.options_files.size(), 1u);
  EXPECT_EQ(cl.options_files[0].path, "o.txt");
  ASSERT_EQ(argc, 4);
  EXPECT_STREQ(argv[1], "deck.yaml");
  EXPECT_STREQ(argv[2], "-steps");
  EXPECT_STREQ(argv[3], "5");
  EXPECT_EQ(argv[4], nullptr);
}

TEST(CommandLine, HelpPetscKeepsHelpForPetsc) {
  std::vector<std::string> words = {"morphogen", "-help", "petsc", "-steps", "5"};
  std::vector<char*> argv;
  for (auto& w : words)
    argv.push_back(w.data());
  argv.push_back(nullptr);
  int argc = static_cast<int>(words.size());
  const CommandLine cl = take_command_line(&argc, argv.data());
  EXPECT_EQ(cl.help, CommandLine::Help::Petsc);
  ASSERT_EQ(argc, 4);
  EXPECT_STREQ(argv[1], "-help");
  EXPECT_STREQ(argv[2], "-steps");
}

TEST(CommandLine, OptionsFileWithoutName) {
  std::vector<std::string> words = {"morphogen", "-options_file"};
  std::vector<char*> argv;
  for (auto& w : words)
    argv.push_back(w.data());
  argv.push_back(nullptr);
  int argc = 2;
  EXPECT_EQ(take_command_line(&argc, argv.data()).error,
            "-options_file: needs a file name (-options_file FILE)");
}

TEST(PathCheck, TooLongNamesAreRefusedBeforeCreation) {
  EXPECT_EQ(directory_name_problem("some/out"), "");
  EXPECT_NE(directory_name_problem(std::string(300, 'a')).find("directory name of 300"),
            std::string::npos);
  std::string deep;
  for (int i = 0; i < 2100; ++i)
    deep += "d/";
  EXPECT_NE(directory_name_problem(deep).find("path of"), std::string::npos);
}

TEST(Format, NumbersForPeople) {
  EXPECT_EQ(format_number(11249.999999999998), "11250");
  EXPECT_EQ(format_number(0.5), "0.5");
  EXPECT_EQ(format_number(1e-12), "1e-12");
  EXPECT_EQ(format_double(11249.999999999998), "11249.999999999998"); // files keep all digits
  EXPECT_EQ(allowed_range(0, std::numeric_limits<double>::max()), "allowed >= 0");
  EXPECT_EQ(allowed_range(0, Options::inf), "allowed >= 0");
  EXPECT_EQ(allowed_range(0, 1e6), "allowed [0, 1000000]");
  EXPECT_EQ(format_number(1e15), "1e+15");
  EXPECT_EQ(allowed_range(-Options::inf, 1), "allowed <= 1");
  EXPECT_EQ(one_line("a\n  b\n"), "a b");
}
