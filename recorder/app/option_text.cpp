// The option table as people read it: --help's list and the documentation's
// tables.
#include <sstream>

#include "app/option_table.h"

namespace wircam::recorder {

namespace {

// `code` → code, [text](link) → text: what a terminal shows of the help.
std::string plain(const std::string& markdown) {
  std::string out;
  for (size_t i = 0; i < markdown.size(); ++i) {
    char c = markdown[i];
    if (c == '`') continue;
    if (c == ']' && i + 1 < markdown.size() && markdown[i + 1] == '(') {
      i = markdown.find(')', i);
      if (i == std::string::npos) break;
      continue;
    }
    if (c == '[' && markdown.find("](", i) < markdown.find(' ', i)) continue;
    out += c;
  }
  return out;
}

// Words filled into lines of `width`, each after `indent` spaces but the
// first, which continues `first`.
std::string wrap(std::string first, const std::string& text, size_t indent, size_t width) {
  std::istringstream words(text);
  std::string word, out;
  std::string line = std::move(first);
  bool fresh = true;  // no word on this line yet
  while (words >> word) {
    if (!fresh && line.size() + 1 + word.size() > width) {
      out += line + "\n";
      line = std::string(indent, ' ');
      fresh = true;
    }
    line += (fresh ? "" : " ") + word;
    fresh = false;
  }
  return out + line + "\n";
}

std::string synopsis(const OptionSpec& spec) {
  std::string text = std::string("--") + spec.name;
  if (spec.value) text += std::string(" ") + spec.value;
  return text;
}

bool meaningful(const char* fallback) {
  std::string f = fallback;
  return !f.empty() && f != "none" && f != "off";
}

std::string cell(std::string text) {
  for (size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2))
    text.replace(at, 1, "\\|");
  return text;
}

}  // namespace

std::string optionsHelp() {
  constexpr size_t kColumn = 25, kWidth = 79;
  std::string out;
  for (const char* section : optionSections()) {
    out += std::string(section) + ":\n";
    for (const auto& spec : optionTable()) {
      if (std::string(spec.section) != section) continue;
      std::string help = plain(spec.help);
      if (meaningful(spec.fallback)) help += std::string(" (default ") + spec.fallback + ")";
      std::string name = std::string(spec.name) == "help" ? "-h, --help" : synopsis(spec);
      std::string head = "  " + name;
      if (head.size() + 1 < kColumn)
        out += wrap(head + std::string(kColumn - head.size(), ' '), help, kColumn, kWidth);
      else
        out += head + "\n" + wrap(std::string(kColumn, ' '), help, kColumn, kWidth);
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
      out +=
          "| `" + std::string(key.key) + "=" + cell(key.value) + "` | " + cell(key.help) + " |\n";
    return out;
  }
  out += "| option | default | config key | reload | what it does |\n|---|---|---|---|---|\n";
  for (const auto& spec : optionTable()) {
    if (section != spec.section) continue;
    std::string name =
        std::string(spec.name) == "help" ? "`-h`, `--help`" : "`" + cell(synopsis(spec)) + "`";
    std::string key = spec.commandLineOnly ? "" : "`" + std::string(spec.name) + "`";
    if (spec.deviceKey) key += ", `[device]` `" + std::string(spec.deviceKey) + "`";
    std::string reload = spec.commandLineOnly ? "" : spec.reloadable ? "yes" : "restart";
    out += "| " + name + " | " + cell(spec.fallback) + " | " + key + " | " + reload + " | " +
           cell(spec.help) + " |\n";
  }
  return out;
}

}  // namespace wircam::recorder
