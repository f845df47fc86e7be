#include "cli_options.h"

#include <getopt.h>

#include <cstdio>
#include <cstdlib>

namespace wircam::cli {

using std::chrono::milliseconds;

const char* const kUsage = R"(Usage: wirc-cli COMMAND [OPTIONS]

Talk to a WiRC device (or wirc-sim) from the shell.

Commands:
  discover                     list the devices that answer discovery
  info                         log in and show the device's cameras, connection and status
  transmitters                 list the logged-in transmitters (TLR)
  request-control ID           ask for the control right to go to connection ID (AREQ);
                               exits 1 with the reason when the device denies it
  configure [--periods US,..] [--failsafe US,..]
                               set channel periods (CCFG) and failsafe values (FCFG);
                               12 comma-separated values, or one for all channels
  set-name NAME                rename the device (DCFG; after its next restart)
  wifi --ssid S --country CC [--password-stdin] [--station] [--channel N]
                               WiFi settings (WCFG); CC is the two-letter country
                               code the radio's channels and power obey (e.g. HU,
                               US); the password is read from stdin and never
                               printed or logged
  extout --destination D --data HEX
                               send bytes out of an external port (EXTOUT): D is
                               null (0x00), uart (0x01), spi-data (0x81),
                               spi-command (0x82) or a number; at most 254 bytes
  firmware-update --md5 HEX    announce a firmware image by its MD5 (FWUP, 32 hex
                               digits); the device disconnects everyone and restarts
  stream --camera N --out FILE.mjpeg|DIR [--frames N] [--duration S]
                               save whole frames: concatenated to a file, or one
                               JPEG per frame into a folder
  stream --camera N --to-port P --duration S
                               hold the login and have the device stream to UDP
                               port P of this host, for another app (e.g.
                               udpsrc ! wircdepay)
  drive --steering US --throttle US [--duration S]
                               send these pulses for at most 10 s, then neutral
                               (steering on channel 1, throttle on channel 2)
  decode [--raw]               read messages (hex text, or raw bytes with --raw) on
                               stdin; print one JSON object per message
  encode [--raw]               read JSON objects (one per line) on stdin; print
                               each message as hex (or raw bytes with --raw)
  compare-commands RECORDED... REPLAYED.jsonl [--json]
                               a recorded drive's commands (the recorder's sidecars,
                               their "control" lines: files, or a recordings
                               folder) against those its replay drew (wirc-sim
                               --replay --commands-out), frame by frame (the
                               same segment, the same time in it):
                               the frames compared, mean and max |Δ| of steering
                               and throttle (µs), how far each steers from
                               neutral, the frames where one steers left and the
                               other right (±10 µs is straight ahead), and the
                               longest run of them; --json: one JSON object

RCOIP and BTEMP vehicles (--protocol rcoip|btemp; port default 9048, 16980):
  drive --protocol P --host H --port N --steering US --throttle US --duration S
                               steer, then neutral; prints each status reply
                               (RCOIP battery and RSSI, BTEMP pins)
  info --protocol P --host H [--port N]
                               the vehicle's status (RCOIP: sends neutral
                               commands, which the receiver answers)
  discover --protocol btemp [--host H --port N]
                               PING the broadcast ports 16980..17079 (or one
                               robot) and list the robots that answer

Marvelmind indoor positions:
  positions --marvelmind HOST:PORT --beacon ADDR[,ADDR...] --count N
                               ask the dashboard for the beacon's position (at
                               --rate HZ, default 10) and print N new ones, one
                               JSON object per line: {"beacon":5,"x":1.234,
                               "y":-0.5,"z":0.25,"timestamp":12.5} (metres;
                               seconds of the dashboard's clock). Exits 1 when
                               no new position comes for --timeout MS.
                               --listen PORT: stream mode, the dashboard pushes
                               to PORT; --units cm|mm: what to ask for (default
                               cm); --timestamp 64|ms: the dashboard's unit
                               (default 1/64 s, as the protocol text)

Connection options (all commands but decode/encode):
  --protocol wirc|rcoip|btemp  what the vehicle speaks (default wirc)
  --host ADDR                  device address (default: discover)
  --port N                     control port (default 1984)
  --device NAME                when discovering: the name or serial to pick
  --discovery-address ADDR     where discovery is sent (default 255.255.255.255)
  --name NAME                  transmitter name (default wirc-cli)
  --priority N                 transmitter priority 0..255 (default 0)
  --timeout MS                 discovery/login/answer timeout (default 3000)

Exit codes: 0 success, 1 failure (device unreachable, refused, ERR), 2 bad usage.
)";

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
  enum {
    kHost = 1000,
    kPort,
    kDevice,
    kDiscovery,
    kName,
    kPriority,
    kTimeout,
    kPeriods,
    kFailsafe,
    kSsid,
    kPasswordStdin,
    kStation,
    kChannel,
    kCountry,
    kCamera,
    kOut,
    kFrames,
    kDuration,
    kSteering,
    kThrottle,
    kRaw,
    kJson,
    kToPort,
    kDestination,
    kData,
    kMd5,
    kProtocol,
    kMarvelmind,
    kBeacon,
    kCount,
    kListen,
    kRate,
    kUnits,
    kTimestampUnit
  };
  static const option options[] = {{"host", required_argument, nullptr, kHost},
                                   {"port", required_argument, nullptr, kPort},
                                   {"device", required_argument, nullptr, kDevice},
                                   {"discovery-address", required_argument, nullptr, kDiscovery},
                                   {"name", required_argument, nullptr, kName},
                                   {"priority", required_argument, nullptr, kPriority},
                                   {"timeout", required_argument, nullptr, kTimeout},
                                   {"periods", required_argument, nullptr, kPeriods},
                                   {"failsafe", required_argument, nullptr, kFailsafe},
                                   {"ssid", required_argument, nullptr, kSsid},
                                   {"password-stdin", no_argument, nullptr, kPasswordStdin},
                                   {"station", no_argument, nullptr, kStation},
                                   {"channel", required_argument, nullptr, kChannel},
                                   {"country", required_argument, nullptr, kCountry},
                                   {"camera", required_argument, nullptr, kCamera},
                                   {"out", required_argument, nullptr, kOut},
                                   {"frames", required_argument, nullptr, kFrames},
                                   {"duration", required_argument, nullptr, kDuration},
                                   {"steering", required_argument, nullptr, kSteering},
                                   {"throttle", required_argument, nullptr, kThrottle},
                                   {"raw", no_argument, nullptr, kRaw},
                                   {"json", no_argument, nullptr, kJson},
                                   {"to-port", required_argument, nullptr, kToPort},
                                   {"destination", required_argument, nullptr, kDestination},
                                   {"data", required_argument, nullptr, kData},
                                   {"md5", required_argument, nullptr, kMd5},
                                   {"protocol", required_argument, nullptr, kProtocol},
                                   {"marvelmind", required_argument, nullptr, kMarvelmind},
                                   {"beacon", required_argument, nullptr, kBeacon},
                                   {"count", required_argument, nullptr, kCount},
                                   {"listen", required_argument, nullptr, kListen},
                                   {"rate", required_argument, nullptr, kRate},
                                   {"units", required_argument, nullptr, kUnits},
                                   {"timestamp", required_argument, nullptr, kTimestampUnit},
                                   {"help", no_argument, nullptr, 'h'},
                                   {nullptr, 0, nullptr, 0}};
  Options o;
  optind = 2;
  int opt;
  while ((opt = getopt_long(argc, argv, "h", options, nullptr)) != -1) {
    switch (opt) {
      case 'h':
        std::fputs(kUsage, stdout);
        std::exit(0);
      case kHost:
        o.host = optarg;
        break;
      case kPort:
        o.port = static_cast<uint16_t>(integer(optarg, "--port", 1, 65535));
        o.portGiven = true;
        break;
      case kProtocol:
        o.protocol = optarg;
        if (o.protocol != "wirc" && o.protocol != "rcoip" && o.protocol != "btemp")
          usageError("--protocol is wirc, rcoip or btemp, not '" + o.protocol + "'");
        break;
      case kDevice:
        o.device = optarg;
        break;
      case kDiscovery:
        o.discoveryAddress = optarg;
        break;
      case kName:
        o.name = optarg;
        break;
      case kPriority:
        o.priority = static_cast<uint8_t>(integer(optarg, "--priority", 0, 255));
        break;
      case kTimeout:
        o.timeout = milliseconds(integer(optarg, "--timeout", 10, 600000));
        break;
      case kPeriods:
        o.periods = optarg;
        break;
      case kFailsafe:
        o.failsafe = optarg;
        break;
      case kSsid:
        o.ssid = optarg;
        break;
      case kPasswordStdin:
        o.passwordStdin = true;
        break;
      case kStation:
        o.station = true;
        break;
      case kChannel:
        o.channel = static_cast<int>(integer(optarg, "--channel", 1, 165));
        break;
      case kCountry:
        o.country = optarg;
        break;
      case kCamera:
        o.camera = static_cast<int>(integer(optarg, "--camera", 0, 255));
        break;
      case kOut:
        o.out = optarg;
        break;
      case kFrames:
        o.frames = static_cast<int>(integer(optarg, "--frames", 1, 100000000));
        break;
      case kDuration:
        o.duration = static_cast<double>(integer(optarg, "--duration", 0, 100000000));
        break;
      case kSteering:
        o.steering = static_cast<int>(integer(optarg, "--steering", 800, 2200));
        break;
      case kThrottle:
        o.throttle = static_cast<int>(integer(optarg, "--throttle", 800, 2200));
        break;
      case kJson:
        o.json = true;
        break;
      case kRaw:
        o.raw = true;
        break;
      case kToPort:
        o.toPort = static_cast<uint16_t>(integer(optarg, "--to-port", 1, 65535));
        break;
      case kDestination:
        o.destination = optarg;
        break;
      case kData:
        o.data = optarg;
        break;
      case kMd5:
        o.md5 = optarg;
        break;
      case kMarvelmind:
        o.positions.dashboard = optarg;
        break;
      case kBeacon:
        o.positions.beacons = optarg;
        break;
      case kCount:
        o.positions.count = static_cast<int>(integer(optarg, "--count", 1, 100000000));
        break;
      case kListen:
        o.positions.listenPort = static_cast<uint16_t>(integer(optarg, "--listen", 0, 65535));
        break;
      case kRate:
        o.positions.rate = static_cast<double>(integer(optarg, "--rate", 1, 100));
        break;
      case kUnits:
        if (std::string(optarg) != "cm" && std::string(optarg) != "mm")
          usageError("--units is cm or mm");
        o.positions.resolution = std::string(optarg) == "mm" ? marvelmind::Resolution::kMillimetres
                                                             : marvelmind::Resolution::kCentimetres;
        break;
      case kTimestampUnit:
        if (std::string(optarg) != "64" && std::string(optarg) != "ms")
          usageError("--timestamp is 64 (1/64 s) or ms");
        o.positions.timestampUnit = std::string(optarg) == "ms"
                                        ? marvelmind::TimestampUnit::kMilliseconds
                                        : marvelmind::TimestampUnit::kSixtyFourths;
        break;
      default:
        usageError("unknown option");
    }
  }
  for (int i = optind; i < argc; ++i) o.positional.emplace_back(argv[i]);
  return o;
}

}  // namespace wircam::cli
