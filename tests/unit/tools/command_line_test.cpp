// A declared command line: parsed, refused and documented from one table.
#include "common/command_line.h"

#include <gtest/gtest.h>

#include <vector>

namespace wircam::command_line {
namespace {

struct Settings {
  double rate = 1;
  int count = 0;
  std::string mode = "a";
  bool loud = false;
};

CommandLine declared(Settings& s) {
  return CommandLine({{"Things",
                       {{"rate", "HZ", "1", "how often, `per second`", number(s.rate, 0.5, 10)},
                        {"count", "N", nullptr, "how many", whole(s.count, 1, 5)},
                        {"mode", "a|b", "a", "which [way](x.md)", oneOf(s.mode, {"a", "b"})},
                        {"loud", nullptr, nullptr, "say more", flag(s.loud)}}}});
}

Expected<std::vector<std::string>, std::string> parse(Settings& s, std::vector<std::string> args,
                                                      bool* help = nullptr) {
  std::vector<char*> argv;
  for (auto& arg : args) argv.push_back(arg.data());
  return declared(s).parse(static_cast<int>(argv.size()), argv.data(), help);
}

TEST(CommandLine, AppliesEachOptionAndKeepsTheRestInOrder) {
  Settings s;
  bool help = true;
  auto rest = parse(
      s, {"tool", "one", "--rate", "2.5", "--count=3", "two", "--loud", "--mode", "b"}, &help);
  ASSERT_TRUE(rest) << rest.error();
  EXPECT_EQ(*rest, (std::vector<std::string>{"one", "two"}));
  EXPECT_EQ(s.rate, 2.5);
  EXPECT_EQ(s.count, 3);
  EXPECT_EQ(s.mode, "b");
  EXPECT_TRUE(s.loud);
  EXPECT_FALSE(help);
}

TEST(CommandLine, RefusesInTheToolsWordsNamingTheOption) {
  Settings s;
  EXPECT_EQ(parse(s, {"tool", "--rate", "11"}).error(),
            "--rate wants a number in 0.5..10, not '11'");
  EXPECT_EQ(parse(s, {"tool", "--count", "2.5"}).error(),
            "--count wants a whole number in 1..5, not '2.5'");
  EXPECT_EQ(parse(s, {"tool", "--count", "0x2"}).error(),
            "--count wants a whole number in 1..5, not '0x2'");
  EXPECT_EQ(parse(s, {"tool", "--count", "1e0"}).error(),
            "--count wants a whole number in 1..5, not '1e0'");
  EXPECT_EQ(parse(s, {"tool", "--rate", "0x5"}).error(),
            "--rate wants a number in 0.5..10, not '0x5'");
  EXPECT_EQ(parse(s, {"tool", "--loud=1"}).error(), "--loud takes no value");
  EXPECT_EQ(parse(s, {"tool", "--mode", "c"}).error(), "--mode is a or b, not 'c'");
  EXPECT_EQ(parse(s, {"tool", "--rate"}).error(), "--rate wants a value");
  EXPECT_EQ(parse(s, {"tool", "--nope"}).error(), "unknown option --nope");
}

TEST(CommandLine, SaysWhetherHelpWasAskedFor) {
  Settings s;
  bool help = false;
  ASSERT_TRUE(parse(s, {"tool", "-h"}, &help));
  EXPECT_TRUE(help);
  ASSERT_TRUE(parse(s, {"tool", "--help"}, &help));
  EXPECT_TRUE(help);
}

TEST(CommandLine, HelpAndDocsComeFromTheSameRows) {
  Settings s;
  auto line = declared(s);
  EXPECT_EQ(line.help(),
            "\nThings:\n"
            "  --rate HZ            how often, per second (default 1)\n"
            "  --count N            how many\n"
            "  --mode a|b           which way (default a)\n"
            "  --loud               say more\n");
  EXPECT_EQ(line.markdown("Things"),
            "| option | default | what it does |\n|---|---|---|\n"
            "| `--rate HZ` | 1 | how often, `per second` |\n"
            "| `--count N` |  | how many |\n"
            "| `--mode a\\|b` | a | which [way](x.md) |\n"
            "| `--loud` |  | say more |\n");
}

}  // namespace
}  // namespace wircam::command_line
