// wirc-cli's command line: the options all commands share and those of
// each, parsed once; the usage text; how a command ends in error.
#pragma once

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/command_line.h"
#include "positions_command.h"
#include "wirc/messages.h"

namespace wircam::cli {

struct Options {
  std::string protocol = "wirc";
  std::string host;
  uint16_t port = wirc::kDefaultPort;
  bool portGiven = false;
  std::string device;
  std::string discoveryAddress = "255.255.255.255";
  std::string name = "wirc-cli";
  uint8_t priority = 0;
  std::chrono::milliseconds timeout{3000};

  // Command-specific.
  std::optional<std::string> periods, failsafe, ssid, out, country, destination, data, md5;
  bool passwordStdin = false, station = false, raw = false, json = false;
  int camera = 0, channel = 1;
  std::optional<int> frames;
  std::optional<uint16_t> toPort;
  double duration = 0;
  std::optional<int> steering, throttle;
  std::vector<std::string> positional;
  cli::PositionsOptions positions;
};

// The declaration of its options (each once), read into `options` (which
// must outlive it), and the whole of --help.
command_line::CommandLine cliCommandLine(Options& options);
std::string cliUsage();

// Bad usage: the message on stderr, exit code 2.
[[noreturn]] void usageError(const std::string& message);
// A failure (unreachable, refused, ERR): the message on stderr, exit code 1.
[[noreturn]] void fail(const std::string& message);
// `text` as a whole number in min..max, or a usage error naming `what`.
long integer(const char* text, const char* what, long min, long max);
// argv[1] is the command; the options and positional arguments follow.
Options parse(int argc, char** argv);

}  // namespace wircam::cli
