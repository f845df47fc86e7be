#include "common/command_line.h"

#include <getopt.h>

#include <cmath>
#include <cstdlib>
#include <sstream>

namespace wircam::command_line {

namespace {

std::string synopsis(const Option& option) {
  std::string text = std::string("--") + option.name;
  if (option.value) text += std::string(" ") + option.value;
  return text;
}

std::string withDefault(const Option& option) {
  std::string help = option.help;
  if (option.fallback) help += std::string(" (default ") + option.fallback + ")";
  return help;
}

}  // namespace

std::string plainText(const std::string& markdown) {
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

std::string tableCell(std::string text) {
  for (size_t at = text.find('|'); at != std::string::npos; at = text.find('|', at + 2))
    text.replace(at, 1, "\\|");
  return text;
}

std::string wrapped(std::string first, const std::string& text, size_t indent, size_t width) {
  std::istringstream words(text);
  std::string word, out, line = std::move(first);
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

CommandLine::CommandLine(std::vector<Section> sections, size_t helpColumn)
    : sections_(std::move(sections)), helpColumn_(helpColumn) {}

Expected<std::vector<std::string>, std::string> CommandLine::parse(int argc, char** argv,
                                                                   bool* helpAsked) const {
  std::vector<const Option*> byIndex;
  std::vector<option> table;
  for (const auto& section : sections_)
    for (const auto& declared : section.options) {
      table.push_back({declared.name, declared.value ? required_argument : no_argument, nullptr,
                       static_cast<int>(1000 + byIndex.size())});
      byIndex.push_back(&declared);
    }
  table.push_back({"help", no_argument, nullptr, 'h'});
  table.push_back({nullptr, 0, nullptr, 0});
  if (helpAsked) *helpAsked = false;
  optind = 0;  // glibc's way to start afresh (a test parses many times)
  opterr = 0;  // said here, in the tool's words
  int found;
  while ((found = getopt_long(argc, argv, ":h", table.data(), nullptr)) != -1) {
    if (found == 'h') {
      if (helpAsked) *helpAsked = true;
      continue;
    }
    if (found == '?' || found == ':') {
      std::string given = argv[optind - 1];
      bool known = optopt >= 1000 && optopt < 1000 + static_cast<int>(byIndex.size());
      if (known && !byIndex[static_cast<size_t>(optopt - 1000)]->value)
        return unexpected(given.substr(0, given.find('=')) + " takes no value");
      if (found == ':' || known) return unexpected(given + " wants a value");
      return unexpected("unknown option " + given);
    }
    const Option& declared = *byIndex[static_cast<size_t>(found - 1000)];
    if (auto problem = declared.apply(declared.value ? optarg : nullptr))
      return unexpected(std::string("--") + declared.name + " " + *problem);
  }
  std::vector<std::string> rest(argv + optind, argv + argc);
  return rest;
}

std::string CommandLine::help() const {
  constexpr size_t kWidth = 79;
  const size_t kColumn = helpColumn_;
  std::string out;
  for (const auto& section : sections_) {
    out += std::string("\n") + section.title + ":\n";
    for (const auto& option : section.options) {
      std::string head = "  " + synopsis(option);
      bool longHead = head.size() + 1 > kColumn;
      if (!longHead) head += std::string(kColumn - head.size(), ' ');
      // A long option and value get a line of their own.
      if (longHead)
        out += head + "\n" +
               wrapped(std::string(kColumn, ' '), plainText(withDefault(option)), kColumn, kWidth);
      else
        out += wrapped(head, plainText(withDefault(option)), kColumn, kWidth);
    }
  }
  return out;
}

std::string CommandLine::markdown(const std::string& title) const {
  std::string out = "| option | default | what it does |\n|---|---|---|\n";
  for (const auto& section : sections_) {
    if (title != section.title) continue;
    for (const auto& option : section.options)
      out += "| `" + tableCell(synopsis(option)) + "` | " +
             (option.fallback ? tableCell(option.fallback) : "") + " | " + tableCell(option.help) +
             " |\n";
  }
  return out;
}

std::string rangeText(double low, double high) {
  // Whole bounds as whole numbers (4294967295, not 4.29497e+09).
  auto said = [](double bound) {
    std::ostringstream text;
    if (bound == std::floor(bound) && std::fabs(bound) < 1e15)
      text << static_cast<long long>(bound);
    else
      text << bound;
    return text.str();
  };
  return said(low) + ".." + said(high);
}

Apply number(double& field, double low, double high) {
  return [&field, low, high](const char* value) -> Problem {
    char* end = nullptr;
    double read = std::strtod(value, &end);
    // Decimal only: strtod would also read 0x10 as 16.
    bool decimal = std::string_view(value).find_first_of("xX") == std::string_view::npos;
    if (end == value || *end != '\0' || !decimal || !std::isfinite(read) || read < low ||
        read > high)
      return "wants a number in " + rangeText(low, high) + ", not '" + value + "'";
    field = read;
    return std::nullopt;
  };
}

Apply text(std::string& field) {
  return [&field](const char* value) -> Problem {
    field = value;
    return std::nullopt;
  };
}

Apply optionalText(std::optional<std::string>& field) {
  return [&field](const char* value) -> Problem {
    field = value;
    return std::nullopt;
  };
}

Apply flag(bool& field) {
  return [&field](const char*) -> Problem {
    field = true;
    return std::nullopt;
  };
}

Apply oneOf(std::string& field, std::vector<std::string> choices) {
  return [&field, choices = std::move(choices)](const char* value) -> Problem {
    for (const auto& choice : choices)
      if (choice == value) {
        field = value;
        return std::nullopt;
      }
    std::string said = "is ";
    for (size_t i = 0; i < choices.size(); ++i)
      said += (i == 0 ? "" : i + 1 == choices.size() ? " or " : ", ") + choices[i];
    return said + ", not '" + value + "'";
  };
}

}  // namespace wircam::command_line
