// A tool's command line, each option declared once: its name, what value
// follows it, its default, its help and how its value is read and checked.
// Parsing (getopt_long's table), --help's list and the documentation's
// Markdown tables all come from the declaration, so they cannot disagree
// (wirc-recorder's own table, recorder/app/option_table.h, also says which
// options a reload takes and which a [device] group may set).
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "common/expected.h"

namespace wircam::command_line {

// Why a value was refused ("wants a number in 1..255, not 'x'"), or nothing.
using Problem = std::optional<std::string>;
// Reads an option's value (null for a flag) into the tool's settings.
using Apply = std::function<Problem(const char* value)>;

struct Option {
  const char* name;      // --name
  const char* value;     // what follows it in --help ("N", "wirc|rcoip"); null: a flag
  const char* fallback;  // the default, as the help says it; null: none worth saying
  const char* help;      // `code` and [text](link) are stripped for --help
  Apply apply;
};

struct Section {
  const char* title;  // heads the options in --help and a table in the docs
  std::vector<Option> options;
};

class CommandLine {
 public:
  // --help's text starts at `helpColumn` (after the option and its value).
  explicit CommandLine(std::vector<Section> sections, size_t helpColumn = 23);

  // Reads argv[1..] (argv[0] is the program, or the command before these
  // options): each option's value applied, in the order given. The
  // arguments that are not options, or the first problem as a usage error
  // says it ("--fps wants a number in 0.1..240, not 'x'"). --help and -h
  // are the caller's: `helpAsked` says whether one was given.
  Expected<std::vector<std::string>, std::string> parse(int argc, char** argv,
                                                        bool* helpAsked = nullptr) const;
  // --help's list of options, section by section.
  std::string help() const;
  // One section's Markdown table (| option | default | what it does |), as
  // the docs hold it between <!-- NAME options: SECTION --> and
  // <!-- /options -->.
  std::string markdown(const std::string& section) const;
  const std::vector<Section>& sections() const { return sections_; }

 private:
  std::vector<Section> sections_;
  size_t helpColumn_;
};

// Readers of the common kinds of value, each saying a refusal the same way.
Apply number(double& field, double low, double high);
// "0..4294967295", as refusals say a range.
std::string rangeText(double low, double high);
// Digits only (an optional minus first): not 1e3, not 0x10, not 1.5.
template <typename Whole>
Apply whole(Whole& field, double low, double high) {
  return [&field, low, high](const char* value) -> Problem {
    std::string_view text = value;
    bool digits = !text.empty() &&
                  text.find_first_not_of("0123456789", text[0] == '-') == std::string_view::npos &&
                  text != "-";
    double read = 0;
    if (!digits || number(read, low, high)(value))
      return "wants a whole number in " + rangeText(low, high) + ", not '" + std::string(text) +
             "'";
    field = static_cast<Whole>(read);
    return std::nullopt;
  };
}
// A whole number that sets an optional field.
template <typename Whole>
Apply optionalWhole(std::optional<Whole>& field, double low, double high) {
  return [&field, low, high](const char* value) -> Problem {
    Whole read{};
    if (auto problem = whole(read, low, high)(value)) return problem;
    field = read;
    return std::nullopt;
  };
}
Apply text(std::string& field);
Apply optionalText(std::optional<std::string>& field);
Apply flag(bool& field);
// One of `choices`, said as "is A, B or C" when it is not.
Apply oneOf(std::string& field, std::vector<std::string> choices);

// One of the choices' names, setting the field to what it means.
template <typename T>
Apply choice(T& field, std::vector<std::pair<std::string, T>> choices) {
  return [&field, choices](const char* value) -> Problem {
    std::vector<std::string> names;
    for (const auto& [name, meaning] : choices) {
      if (name == value) {
        field = meaning;
        return std::nullopt;
      }
      names.push_back(name);
    }
    std::string unused;
    return oneOf(unused, names)(value);
  };
}

// --help's text without Markdown: `code` → code, [text](link) → text.
std::string plainText(const std::string& markdown);
// Text for a cell of a Markdown table: its bars escaped.
std::string tableCell(std::string text);
// `text`'s words filled into lines of `width`, the first continuing
// `first`, the others after `indent` spaces.
std::string wrapped(std::string first, const std::string& text, size_t indent, size_t width);

}  // namespace wircam::command_line
