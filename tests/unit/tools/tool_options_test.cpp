// wirc-sim's and wirc-cli's options as declared: read as the tools read
// them, and docs/tools.md's tables held to the declarations.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli_options.h"
#include "sim_options.h"

namespace wircam::sim {
namespace {

// Each section's table in the page, between <!-- TOOL options: SECTION -->
// and <!-- /options -->, is the declaration's; WIRCAM_UPDATE_DOCS=1
// rewrites them.
void expectDocumentedIn(const char* page, const std::string& tool,
                        const command_line::CommandLine& line) {
  auto path = std::filesystem::path(WIRCAM_SOURCE_DIR) / page;
  std::ifstream in(path);
  std::stringstream read;
  read << in.rdbuf();
  std::string text = read.str();
  bool update = std::getenv("WIRCAM_UPDATE_DOCS") != nullptr;
  for (const auto& section : line.sections()) {
    std::string open = "<!-- " + tool + " options: " + section.title + " -->\n";
    size_t begin = text.find(open);
    ASSERT_NE(begin, std::string::npos) << page << " lacks " << open;
    begin += open.size();
    size_t end = text.find("<!-- /options -->", begin);
    ASSERT_NE(end, std::string::npos);
    std::string expected = line.markdown(section.title);
    if (update) {
      text.replace(begin, end - begin, expected);
      continue;
    }
    EXPECT_EQ(text.substr(begin, end - begin), expected)
        << page << "'s " << section.title << " table is not " << tool
        << "'s: WIRCAM_UPDATE_DOCS=1 ctest -R Options.TheDocumentations";
  }
  if (update) std::ofstream(path) << text;
}

Expected<std::optional<SimOptions>, std::string> parse(std::vector<std::string> args) {
  args.insert(args.begin(), "wirc-sim");
  std::vector<char*> argv;
  for (auto& arg : args) argv.push_back(arg.data());
  return parseSimOptions(static_cast<int>(argv.size()), argv.data());
}

TEST(SimOptions, ReadsTheDeviceTheSceneAndTheDashboard) {
  auto parsed = parse({"--port", "0", "--size", "640x480", "--scene", "static", "--tags", "3,7",
                       "--marvelmind", "0", "--marvelmind-timestamp", "ms", "--loss", "0.1"});
  ASSERT_TRUE(parsed) << parsed.error();
  const SimOptions& o = **parsed;
  EXPECT_EQ(o.device.port, 0);
  EXPECT_EQ(o.scene.width, 640);
  EXPECT_TRUE(o.scene.carFixed);
  EXPECT_EQ(o.scene.tagIds, (std::vector<int>{3, 7}));
  ASSERT_TRUE(o.dashboard);
  EXPECT_EQ(o.dashboard->timestampUnit, marvelmind::TimestampUnit::kMilliseconds);
  EXPECT_EQ(o.device.impairments.loss, 0.1);
}

TEST(SimOptions, RefusesWhatDoesNotGoTogether) {
  EXPECT_EQ(parse({"--marvelmind-rate", "5"}).error(),
            "the --marvelmind-* options need --marvelmind PORT");
  EXPECT_EQ(parse({"--frames", "a", "--replay", "b"}).error(),
            "--frames and --replay: one scene at a time");
  EXPECT_EQ(parse({"--loop"}).error(),
            "--camera, --speed, --loop and --commands-out go with --replay");
  EXPECT_EQ(parse({"--size", "big"}).error(),
            "--size wants WIDTHxHEIGHT (16x16..7680x4320), not 'big'");
  EXPECT_EQ(parse({"extra"}).error(), "unexpected argument 'extra'");
}

TEST(SimOptions, HelpIsAskedForAndListsEveryOption) {
  auto parsed = parse({"--help"});
  ASSERT_TRUE(parsed);
  EXPECT_FALSE(*parsed);
  std::string usage = simUsage();
  SimOptions unused;
  auto line = simCommandLine(unused);
  for (const auto& section : line.sections())
    for (const auto& option : section.options)
      EXPECT_NE(usage.find(std::string("--") + option.name + " "), std::string::npos)
          << option.name;
}

TEST(SimOptions, TheDocumentationsTablesAreTheDeclarations) {
  SimOptions unused;
  expectDocumentedIn("docs/tools.md", "wirc-sim", simCommandLine(unused));
}

TEST(CliOptions, TheDocumentationsTablesAreTheDeclarations) {
  cli::Options unused;
  expectDocumentedIn("docs/tools.md", "wirc-cli", cli::cliCommandLine(unused));
}

TEST(CliOptions, RefusesInItsOwnWords) {
  cli::Options unused;
  auto line = cli::cliCommandLine(unused);
  std::vector<std::string> args = {"drive", "--steering", "2300"};
  std::vector<char*> argv;
  for (auto& arg : args) argv.push_back(arg.data());
  EXPECT_EQ(line.parse(3, argv.data()).error(),
            "--steering wants a whole number in 800..2200, not '2300'");
}

}  // namespace
}  // namespace wircam::sim
