// The option table as people read it: --help's list and the documentation's
// tables.
#include "app/option_table.h"
#include "common/command_line.h"

namespace wircam::recorder {

namespace {

std::string synopsis(const OptionSpec& spec) {
  std::string text = std::string("--") + spec.name;
  if (spec.value) text += std::string(" ") + spec.value;
  return text;
}

bool meaningful(const char* fallback) {
  std::string f = fallback;
  return !f.empty() && f != "none" && f != "off";
}

}  // namespace

std::string optionsHelp() {
  constexpr size_t kColumn = 25, kWidth = 79;
  std::string out;
  for (const char* section : optionSections()) {
    out += std::string(section) + ":\n";
    for (const auto& spec : optionTable()) {
      if (std::string(spec.section) != section) continue;
      std::string help = command_line::plainText(spec.help);
      if (meaningful(spec.fallback)) help += std::string(" (default ") + spec.fallback + ")";
      std::string name = std::string(spec.name) == "help" ? "-h, --help" : synopsis(spec);
      std::string head = "  " + name;
      if (head.size() + 1 < kColumn)
        out += command_line::wrapped(head + std::string(kColumn - head.size(), ' '), help, kColumn,
                                     kWidth);
      else
        out +=
            head + "\n" + command_line::wrapped(std::string(kColumn, ' '), help, kColumn, kWidth);
    }
    out += "\n";
  }
  return out;
}

std::string optionsMarkdown(const std::string& section) {
  std::string out;
  if (section == "device") {
    out += "| key | what it does |\n|---|---|\n";
    for (const auto& key : deviceKeyTable())
      out += "| `" + std::string(key.key) + "=" + command_line::tableCell(key.value) + "` | " +
             command_line::tableCell(key.help) + " |\n";
    return out;
  }
  out += "| option | default | config key | reload | what it does |\n|---|---|---|---|---|\n";
  for (const auto& spec : optionTable()) {
    if (section != spec.section) continue;
    std::string name = std::string(spec.name) == "help"
                           ? "`-h`, `--help`"
                           : "`" + command_line::tableCell(synopsis(spec)) + "`";
    std::string key = spec.commandLineOnly ? "" : "`" + std::string(spec.name) + "`";
    if (spec.deviceKey) key += ", `[device]` `" + std::string(spec.deviceKey) + "`";
    std::string reload = spec.commandLineOnly ? "" : spec.reloadable ? "yes" : "restart";
    out += "| " + name + " | " + command_line::tableCell(spec.fallback) + " | " + key + " | " +
           reload + " | " + command_line::tableCell(spec.help) + " |\n";
  }
  return out;
}

}  // namespace wircam::recorder
