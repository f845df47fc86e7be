// Every wirc-recorder option, declared once: its name (the command line's
// --NAME and the config file's key), its value, default, the room it
// configures, whether a [device NAME] group may set it, whether a reload
// takes it, its help, and how its value is read and checked. The command
// line (getopt's table), the config file's reader, --help and the option
// tables in docs/recorder.md all come from here (a unit test holds the
// documentation to it).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "app/recorder_options.h"

namespace wircam::recorder {

// Why a value was refused, or nothing.
using OptionProblem = std::optional<std::string>;

struct OptionSpec {
  const char* name;      // --name, and the key in [recorder]
  const char* value;     // what follows it in --help ("S", "mkv|mp4"); null: a flag
  const char* fallback;  // the default, as the documentation says it
  const char* section;   // the room it configures, as the documentation heads it
  // How a reload treats a change: applied to the cameras it concerns (each
  // restarted alone, the others recording on), or refused (a restart of
  // the recorder takes it).
  bool reloadable = false;
  const char* deviceKey = nullptr;  // the [device NAME] key that overrides it per device, or null
  const char* help;  // Markdown-light: `code` and [text](link) are stripped for --help
  std::function<OptionProblem(RecorderOptions&, const char* value)> apply;
  // A value the tests give it, and the options it cannot be given without.
  const char* example = nullptr;
  std::vector<const char*> needs = {};  // option, value, option, value...
  // --device, --config, --help: not a config file's key.
  bool commandLineOnly = false;
  // "--mqtt-discovery [PREFIX]": the value may be left out.
  bool optionalValue = false;
};

// The [device NAME] keys that only a device has (its host, port, cameras,
// steering target).
struct DeviceKeySpec {
  const char* key;
  const char* value;
  const char* help;
  std::function<OptionProblem(DeviceTarget&, const std::string& value)> apply;
};

const std::vector<OptionSpec>& optionTable();
const OptionSpec* findOption(const std::string& name);
const std::vector<DeviceKeySpec>& deviceKeyTable();
// The sections in the order the documentation and --help show them.
const std::vector<const char*>& optionSections();

// --help's list of options, each wrapped under its name.
std::string optionsHelp();
// One section's Markdown table, as docs/recorder.md has it between
// <!-- options: SECTION --> and <!-- /options -->; "device" for the
// [device NAME] keys.
std::string optionsMarkdown(const std::string& section);

}  // namespace wircam::recorder
