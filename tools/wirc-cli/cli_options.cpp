#include "cli_options.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <set>

namespace wircam::cli {

using command_line::Apply;
using command_line::Problem;
using command_line::whole;
using std::chrono::milliseconds;

namespace {

// The commands' part of --help, each filled to the options' width.
struct CommandHelp {
  const char* synopsis;
  const char* text;
};
struct CommandGroup {
  const char* title;
  std::vector<CommandHelp> commands;
};

const std::vector<CommandGroup> kCommandGroups = {
    {"Commands",
     {
         {"discover", "list the devices that answer discovery"},
         {"info", "log in and show the device's cameras, connection and status"},
         {"transmitters", "list the logged-in transmitters (TLR)"},
         {"request-control ID",
          "ask for the control right to go to connection ID (AREQ); exits 1 with the reason "
          "when the device denies it"},
         {"configure [--periods US,..] [--failsafe US,..]",
          "set channel periods (CCFG) and failsafe values (FCFG); 12 comma-separated values, or "
          "one for all channels"},
         {"set-name NAME", "rename the device (DCFG; after its next restart)"},
         {"wifi --ssid S --country CC [--password-stdin] [--station] [--channel N]",
          "WiFi settings (WCFG); CC is the two-letter country code the radio's channels and "
          "power obey (e.g. HU, US); the password is read from stdin and never printed or "
          "logged"},
         {"extout --destination D --data HEX",
          "send bytes out of an external port (EXTOUT): D is null (0x00), uart (0x01), "
          "spi-data (0x81), spi-command (0x82) or a number; at most 254 bytes"},
         {"firmware-update --md5 HEX",
          "announce a firmware image by its MD5 (FWUP, 32 hex digits); the device disconnects "
          "everyone and restarts"},
         {"stream --camera N --out FILE.mjpeg|DIR [--frames N] [--duration S]",
          "save whole frames: concatenated to a file, or one JPEG per frame into a folder"},
         {"stream --camera N --to-port P --duration S",
          "hold the login and have the device stream to UDP port P of this host, for another "
          "app (e.g. udpsrc ! wircdepay)"},
         {"drive --steering US --throttle US [--duration S]",
          "send these pulses for at most 10 s, then neutral (steering on channel 1, throttle on "
          "channel 2)"},
         {"decode [--raw]",
          "read messages (hex text, or raw bytes with --raw) on stdin; print one JSON object per "
          "message, and an error line for what is no message (exit 1)"},
         {"encode [--raw]",
          "read JSON objects (one per line, every field of the message) on stdin; print each "
          "message as hex (or raw bytes with --raw)"},
         {"compare-commands RECORDED... REPLAYED.jsonl [--json]",
          "a recorded drive's commands (the recorder's sidecars, their \"control\" lines: "
          "files, or a recordings folder) against those its replay drew (wirc-sim --replay "
          "--commands-out), frame by frame (the same segment, the same time in it): the frames "
          "compared, mean and max |Δ| of steering and throttle (µs), how far each steers from "
          "neutral, the frames where one steers left and the other right (±10 µs is straight "
          "ahead), and the longest run of them; --json: one JSON object"},
     }},
    {"RCOIP and BTEMP vehicles (--protocol rcoip|btemp; port default 9048, 16980)",
     {
         {"drive --protocol P --host H --port N --steering US --throttle US --duration S",
          "steer, then neutral; prints each status reply (RCOIP battery and RSSI, BTEMP pins)"},
         {"info --protocol P --host H [--port N]",
          "the vehicle's status (RCOIP: sends neutral commands, which the receiver answers)"},
         {"discover --protocol btemp [--host H --port N]",
          "PING the broadcast ports 16980..17079 (or one robot) and list the robots that "
          "answer"},
     }},
    {"Marvelmind indoor positions",
     {
         {"positions --marvelmind HOST:PORT --beacon ADDR[,ADDR...] --count N",
          "ask the dashboard for the beacon's position (at --rate HZ, default 10) and print N "
          "new ones, one JSON object per line: {\"beacon\": 5, \"x\": 1.234, \"y\": -0.5, "
          "\"z\": 0.25, \"timestamp\": 12.5} (metres; seconds of the dashboard's clock). Exits 1 "
          "when no new position comes for --timeout MS. --listen PORT: stream mode, the "
          "dashboard pushes to PORT; --units cm|mm: what to ask for (default cm); --timestamp "
          "64|ms: the dashboard's unit (default 1/64 s, as the protocol text)"},
     }},
};

constexpr size_t kHelpColumn = 31;  // where both the commands' and the options' help start
constexpr size_t kHelpWidth = 79;

std::string commandsHelp() {
  std::string out =
      "Usage: wirc-cli COMMAND [OPTIONS]\n\nTalk to a WiRC device (or wirc-sim) from the "
      "shell.\n";
  for (const auto& group : kCommandGroups) {
    out += std::string("\n") + group.title + ":\n";
    for (const auto& command : group.commands) {
      std::string head = std::string("  ") + command.synopsis;
      // A long synopsis gets a line of its own (wrapped if it must be).
      if (head.size() + 1 > kHelpColumn)
        out += command_line::wrapped("  ", command.synopsis, 4, kHelpWidth) +
               command_line::wrapped(std::string(kHelpColumn, ' '), command.text, kHelpColumn,
                                     kHelpWidth);
      else
        out += command_line::wrapped(head + std::string(kHelpColumn - head.size(), ' '),
                                     command.text, kHelpColumn, kHelpWidth);
    }
  }
  return out;
}

constexpr const char* kOutro = R"(
  -h, --help                   show this text

Exit codes: 0 success, 1 failure (device unreachable, refused, ERR, input that
is no message), 2 bad usage (an option another command takes is one).
)";

std::vector<command_line::Section> sections(Options& o) {
  auto& p = o.positions;
  return {
      {"Connection options (not for decode, encode, compare-commands, positions)",
       {
           {"protocol", "wirc|rcoip|btemp", "wirc", "what the vehicle speaks",
            command_line::oneOf(o.protocol, {"wirc", "rcoip", "btemp"})},
           {"host", "ADDR", "discover", "the device's address", command_line::text(o.host)},
           {"port", "N", "1984; rcoip 9048, btemp 16980", "its control port",
            [&o](const char* value) -> Problem {
              o.portGiven = true;
              return whole(o.port, 1, 65535)(value);
            }},
           {"device", "NAME", nullptr, "when discovering: the name or serial to pick",
            command_line::text(o.device)},
           {"discovery-address", "ADDR", "255.255.255.255", "where discovery is sent",
            command_line::text(o.discoveryAddress)},
           {"name", "NAME", "wirc-cli", "transmitter name", command_line::text(o.name)},
           {"priority", "N", "0", "transmitter priority 0..255", whole(o.priority, 0, 255)},
           {"timeout", "MS", "3000",
            "discovery, login and answer timeout (positions: how long to wait for a new one)",
            [&o](const char* value) -> Problem {
              int ms = 0;
              if (auto problem = whole(ms, 10, 600000)(value)) return problem;
              o.timeout = milliseconds(ms);
              return std::nullopt;
            }},
       }},
      {"Command options",
       {
           {"periods", "US,...", nullptr, "configure: channel periods (CCFG), 12 values or one",
            command_line::optionalText(o.periods)},
           {"failsafe", "US,...", nullptr, "configure: failsafe values (FCFG), 12 values or one",
            command_line::optionalText(o.failsafe)},
           {"ssid", "S", nullptr, "wifi: the network's name", command_line::optionalText(o.ssid)},
           {"country", "CC", nullptr,
            "wifi: the two-letter country code the radio's channels and power obey (HU, US)",
            command_line::optionalText(o.country)},
           {"password-stdin", nullptr, nullptr,
            "wifi: read the password from stdin (never printed or logged)",
            command_line::flag(o.passwordStdin)},
           {"station", nullptr, nullptr, "wifi: join the network instead of making one",
            command_line::flag(o.station)},
           {"channel", "N", "1", "wifi: the radio channel, 1..165", whole(o.channel, 1, 165)},
           {"destination", "D", nullptr, "extout: null, uart, spi-data, spi-command or a number",
            command_line::optionalText(o.destination)},
           {"data", "HEX", nullptr, "extout: the bytes, at most 254",
            command_line::optionalText(o.data)},
           {"md5", "HEX", nullptr, "firmware-update: the image's MD5, 32 hex digits",
            command_line::optionalText(o.md5)},
           {"camera", "N", "0", "stream: the camera", whole(o.camera, 0, 255)},
           {"out", "FILE.mjpeg|DIR", nullptr,
            "stream: frames concatenated into a file, or one JPEG each into a folder",
            command_line::optionalText(o.out)},
           {"frames", "N", nullptr, "stream: stop after N frames",
            command_line::optionalWhole(o.frames, 1, 100000000)},
           {"duration", "S", nullptr, "stream, drive: how long (drive: at most 10 s)",
            command_line::number(o.duration, 0, 100000000)},
           {"to-port", "P", nullptr,
            "stream: have the device stream to UDP port P of this host, for another app",
            command_line::optionalWhole(o.toPort, 1, 65535)},
           {"steering", "US", nullptr, "drive: the steering pulse (channel 1), 800..2200",
            command_line::optionalWhole(o.steering, 800, 2200)},
           {"throttle", "US", nullptr, "drive: the throttle pulse (channel 2), 800..2200",
            command_line::optionalWhole(o.throttle, 800, 2200)},
           {"raw", nullptr, nullptr, "decode, encode: raw bytes instead of hex text",
            command_line::flag(o.raw)},
           {"json", nullptr, nullptr, "compare-commands: one JSON object",
            command_line::flag(o.json)},
       }},
      {"Marvelmind positions options",
       {
           {"marvelmind", "HOST:PORT", nullptr, "the dashboard", command_line::text(p.dashboard)},
           {"beacon", "ADDR[,ADDR...]", nullptr, "the beacons whose positions to print",
            command_line::text(p.beacons)},
           {"count", "N", "10", "how many new positions to print", whole(p.count, 1, 100000000)},
           {"listen", "PORT", nullptr, "stream mode: the dashboard pushes to PORT",
            command_line::optionalWhole(p.listenPort, 0, 65535)},
           {"rate", "HZ", "10", "how often to ask", command_line::number(p.rate, 1, 100)},
           {"units", "cm|mm", "cm", "what to ask for",
            command_line::choice<marvelmind::Resolution>(
                p.resolution, {{"cm", marvelmind::Resolution::kCentimetres},
                               {"mm", marvelmind::Resolution::kMillimetres}})},
           {"timestamp", "64|ms", "64", "the dashboard's unit: 1/64 s as the protocol text, or ms",
            command_line::choice<marvelmind::TimestampUnit>(
                p.timestampUnit, {{"64", marvelmind::TimestampUnit::kSixtyFourths},
                                  {"ms", marvelmind::TimestampUnit::kMilliseconds}})},
       }},
  };
}

// The options each command takes beyond the connection's (the first
// section's); the commands that take none of those are the last four.
const std::map<std::string, std::set<std::string>> kCommandOptions = {
    {"discover", {}},
    {"info", {}},
    {"transmitters", {}},
    {"request-control", {}},
    {"set-name", {}},
    {"configure", {"periods", "failsafe"}},
    {"wifi", {"ssid", "country", "password-stdin", "station", "channel"}},
    {"extout", {"destination", "data"}},
    {"firmware-update", {"md5"}},
    {"stream", {"camera", "out", "frames", "duration", "to-port"}},
    {"drive", {"steering", "throttle", "duration"}},
};
const std::map<std::string, std::set<std::string>> kCommandsWithoutConnection = {
    {"decode", {"raw"}},
    {"encode", {"raw"}},
    {"compare-commands", {"json"}},
    {"positions",
     {"marvelmind", "beacon", "count", "listen", "rate", "units", "timestamp", "timeout"}},
};

// Whether `command` takes --option (an unknown command is refused later,
// as such).
bool takes(const std::string& command, const std::string& option,
           const std::vector<command_line::Section>& declared) {
  if (auto own = kCommandsWithoutConnection.find(command); own != kCommandsWithoutConnection.end())
    return own->second.count(option) > 0;
  auto own = kCommandOptions.find(command);
  if (own == kCommandOptions.end() || own->second.count(option)) return true;
  const auto& connection = declared.front().options;
  return std::any_of(connection.begin(), connection.end(),
                     [&](const command_line::Option& o) { return option == o.name; });
}

}  // namespace

command_line::CommandLine cliCommandLine(Options& options) {
  return command_line::CommandLine(sections(options), kHelpColumn);
}

std::string cliUsage() {
  Options unused;
  return commandsHelp() + cliCommandLine(unused).help() + kOutro;
}

[[noreturn]] void usageError(const std::string& message) {
  std::fprintf(stderr, "wirc-cli: %s (see wirc-cli --help)\n", message.c_str());
  std::exit(2);
}

[[noreturn]] void fail(const std::string& message) {
  std::fprintf(stderr, "wirc-cli: %s\n", message.c_str());
  std::exit(1);
}

long integer(const char* text, const char* what, long min, long max) {
  char* end = nullptr;
  long value = std::strtol(text, &end, 10);
  if (end == text || *end != '\0' || value < min || value > max)
    usageError(std::string(what) + " wants a whole number in " + std::to_string(min) + ".." +
               std::to_string(max) + ", not '" + text + "'");
  return value;
}

Options parse(int argc, char** argv) {
  Options o;
  bool help = false;
  // Each option read is noted: one the command does not take is a mistake
  // (a misplaced --duration, an --ssid given to info), not to be ignored.
  std::vector<std::string> given;
  auto declared = sections(o);
  for (auto& section : declared)
    for (auto& option : section.options)
      option.apply = [&given, name = option.name, apply = option.apply](const char* value) {
        given.push_back(name);
        return apply(value);
      };
  // argv[1] is the command: the options follow it.
  std::string command = argc > 1 ? argv[1] : "";
  auto rest = command_line::CommandLine(declared, kHelpColumn).parse(argc - 1, argv + 1, &help);
  if (!rest) usageError(rest.error());
  if (help) {
    std::fputs(cliUsage().c_str(), stdout);
    std::exit(0);
  }
  for (const auto& option : given)
    if (!takes(command, option, declared)) usageError(command + " does not take --" + option);
  o.positional = std::move(*rest);
  return o;
}

}  // namespace wircam::cli
