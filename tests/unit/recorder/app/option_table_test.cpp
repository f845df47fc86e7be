// The option table is where --help, the config file's reader, the command
// line and docs/recorder.md come from: each option given on the command
// line and in the config file must mean the same, and what the help and the
// documentation say must be the table's.
#include "app/option_table.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/recorder_options.h"
#include "command_line.h"

namespace wircam::recorder {
namespace {

class ConfigFile {
 public:
  explicit ConfigFile(const std::string& text) {
    char name[] = "/tmp/wircam-options-XXXXXX";
    int fd = mkstemp(name);
    close(fd);
    path_ = name;
    std::ofstream(path_) << text;
  }
  ~ConfigFile() { std::filesystem::remove(path_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
};

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(OptionTable, EveryOptionMeansTheSameOnTheCommandLineAndInTheConfigFile) {
  for (const auto& spec : optionTable()) {
    if (spec.commandLineOnly) continue;
    SCOPED_TRACE(spec.name);
    ASSERT_NE(spec.example, nullptr) << "each option needs an example for this test";
    std::vector<std::string> words;
    std::string config = "[recorder]\n";
    std::vector<std::pair<std::string, std::string>> given = {{spec.name, spec.example}};
    if (std::string(spec.name) != "out") given.push_back({"out", "x"});
    for (size_t i = 0; i + 1 < spec.needs.size(); i += 2)
      given.push_back({spec.needs[i], spec.needs[i + 1]});
    for (const auto& [name, value] : given) {
      const OptionSpec* option = findOption(name);
      ASSERT_NE(option, nullptr) << name;
      words.push_back("--" + name);
      // A flag takes no value on the command line; the config says true.
      if (option->value) words.push_back(value);
      config += name + "=" + value + "\n";
    }
    auto fromCommandLine = parse(words);
    ASSERT_TRUE(fromCommandLine) << fromCommandLine.error();
    ConfigFile file(config);
    auto fromConfig = parse({"--config", file.path()});
    ASSERT_TRUE(fromConfig) << fromConfig.error();
    EXPECT_EQ(fromConfig->configFile, file.path());  // what a reload reads again
    fromConfig->configFile.clear();
    // Both differ from the defaults where the example does, and alike.
    auto defaults = parse({"--out", "x"});
    ASSERT_TRUE(defaults);
    RecorderOptions withoutGiven = *fromCommandLine;
    withoutGiven.given = defaults->given;
    EXPECT_FALSE(withoutGiven == *defaults);
    EXPECT_TRUE(*fromCommandLine == *fromConfig);
  }
}

TEST(OptionTable, AValueAnOptionRefusesIsRefusedAlikeInBothAndNamed) {
  auto commandLine = parse({"--out", "x", "--stall-timeout", "0.1"});
  ASSERT_FALSE(commandLine);
  EXPECT_EQ(commandLine.error(), "--stall-timeout: seconds, 0.5..3600");
  ConfigFile file("[recorder]\nout=x\nstall-timeout=0.1\n");
  auto config = parse({"--config", file.path()});
  ASSERT_FALSE(config);
  EXPECT_EQ(config.error(), file.path() + " [recorder] stall-timeout: seconds, 0.5..3600");
  ConfigFile unknown("[recorder]\nout=x\nstal-timeout=3\n");
  auto misspelt = parse({"--config", unknown.path()});
  ASSERT_FALSE(misspelt);
  EXPECT_NE(misspelt.error().find("stal-timeout: not an option"), std::string::npos)
      << misspelt.error();
}

TEST(OptionTable, DeviceGroupsTakeTheirKeysAndOverrideTheRecorderWideOptions) {
  ConfigFile file(
      "[recorder]\nout=x\ndetect=tag36h11\ncamera=0\n"
      "[device rover]\nhost=10.0.0.2\nport=1985\ncameras=0;1\nfollow=true\n"
      "[device still]\nhost=10.0.0.3\n");
  auto options = parse({"--config", file.path()});
  ASSERT_TRUE(options) << options.error();
  ASSERT_EQ(options->devices.size(), 2u);
  EXPECT_EQ(options->devices[0].label, "rover");
  EXPECT_EQ(options->devices[0].port, 1985);
  EXPECT_EQ(options->devices[0].cameras, (std::vector<int>{0, 1}));
  EXPECT_TRUE(*options->devices[0].follow);
  EXPECT_EQ(options->devices[1].cameras, (std::vector<int>{0}));
  EXPECT_FALSE(*options->devices[1].follow);
  ConfigFile bad("[recorder]\nout=x\n[device rover]\nhost=h\nspeed=3\n");
  auto refused = parse({"--config", bad.path()});
  ASSERT_FALSE(refused);
  EXPECT_NE(refused.error().find("[device rover] speed: unknown key (host, port, cameras"),
            std::string::npos)
      << refused.error();
  // A group without a name made files named "-cam0-...mkv" (a stranger's
  // trial): the name is the stream's.
  ConfigFile unnamed("[recorder]\nout=x\n[device ]\nhost=h\n");
  auto nameless = parse({"--config", unnamed.path()});
  ASSERT_FALSE(nameless);
  EXPECT_NE(nameless.error().find("[device ] needs a name"), std::string::npos) << nameless.error();
}

TEST(OptionTable, HelpNamesEveryOptionWithItsValueAndDefault) {
  std::string help = usage();
  for (const auto& spec : optionTable()) {
    std::string synopsis =
        std::string("--") + spec.name + (spec.value ? std::string(" ") + spec.value : "");
    EXPECT_NE(help.find(synopsis), std::string::npos) << synopsis;
  }
  EXPECT_NE(help.find("  --stall-timeout S      a camera logged in"), std::string::npos) << help;
  EXPECT_NE(help.find("(default 5)"), std::string::npos);
  for (const auto& key : deviceKeyTable()) EXPECT_NE(help.find(key.key), std::string::npos);
  for (const auto& line : {std::string("`"), std::string("](")})
    EXPECT_EQ(optionsHelp().find(line), std::string::npos) << "Markdown left in --help: " << line;
}

// docs/recorder.md holds each section's table between
// <!-- options: SECTION --> and <!-- /options -->. WIRCAM_UPDATE_DOCS=1
// writes them from the table.
TEST(OptionTable, TheDocumentationsTablesAreTheTables) {
  std::filesystem::path page = std::filesystem::path(WIRCAM_SOURCE_DIR) / "docs/recorder.md";
  std::string text = readFile(page);
  std::vector<std::string> sections(optionSections().begin(), optionSections().end());
  sections.push_back("device");
  bool update = getenv("WIRCAM_UPDATE_DOCS") != nullptr;
  for (const auto& section : sections) {
    std::string open = "<!-- options: " + section + " -->\n";
    size_t begin = text.find(open);
    ASSERT_NE(begin, std::string::npos) << "docs/recorder.md lacks " << open;
    begin += open.size();
    size_t end = text.find("<!-- /options -->", begin);
    ASSERT_NE(end, std::string::npos);
    std::string expected = optionsMarkdown(section);
    if (update) {
      text.replace(begin, end - begin, expected);
      continue;
    }
    EXPECT_EQ(text.substr(begin, end - begin), expected)
        << "docs/recorder.md's " << section
        << " table is not the option table's: WIRCAM_UPDATE_DOCS=1 ctest -R OptionTable";
  }
  if (update) std::ofstream(page) << text;
}

TEST(OptionTable, AReloadRefusesWhatTakesARestartAndTakesTheRest) {
  auto running = parse({"--out", "x", "--http", ":8080", "--segment", "60"});
  auto segment = parse({"--out", "x", "--http", ":8080", "--segment", "30"});
  auto server = parse({"--out", "x", "--http", ":8081", "--segment", "60"});
  auto added = parse({"--out", "x", "--http", ":8080", "--segment", "60", "--codec", "h264"});
  ASSERT_TRUE(running && segment && server && added);
  EXPECT_EQ(reloadRefusal(*running, *segment), std::nullopt);
  ASSERT_TRUE(reloadRefusal(*running, *server));
  EXPECT_EQ(reloadRefusal(*running, *server)->rfind("http changed", 0), 0u);
  ASSERT_TRUE(reloadRefusal(*running, *added));
  EXPECT_EQ(reloadRefusal(*running, *added)->rfind("codec changed", 0), 0u);
  // What an option does, not how it was written: its default written out,
  // or a value given twice, is no change.
  auto spelledOut = parse({"--out", "x", "--http", ":8080", "--http", ":8080", "--segment", "60",
                           "--codec", "jpeg", "--status", "1"});
  ASSERT_TRUE(spelledOut);
  EXPECT_EQ(reloadRefusal(*running, *spelledOut), std::nullopt);
}

TEST(OptionTable, AFlagInTheConfigFileIsTrueOrFalseAndNothingElse) {
  ConfigFile no("[recorder]\nout=x\ndetect=tag36h11\nfollow=no\n");
  auto recorderWide = parse({"--config", no.path()});
  ASSERT_FALSE(recorderWide);
  EXPECT_NE(recorderWide.error().find("follow: true or false"), std::string::npos);
  ConfigFile device("[recorder]\nout=x\n[device rover]\nhost=h\nfollow=yes\n");
  auto perDevice = parse({"--config", device.path()});
  ASSERT_FALSE(perDevice);
  EXPECT_NE(perDevice.error().find("follow: true or false"), std::string::npos);
}

}  // namespace
}  // namespace wircam::recorder
