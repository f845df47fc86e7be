// wirc-cli: talk to a WiRC device (or wirc-sim) from a shell. See --help.
#include <getopt.h>
#include <poll.h>
#include <sys/socket.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "cousin_commands.h"
#include "hex.h"
#include "message_json.h"
#include "positions_command.h"
#include "wirc/channel_list.h"
#include "wirc/discovery.h"
#include "wirc/message_stream_parser.h"
#include "wirc/stream_receiver.h"
#include "wirc/transmitter_session.h"

using namespace wircam;
using std::chrono::milliseconds;

namespace {

constexpr const char* kUsage = R"(Usage: wirc-cli COMMAND [OPTIONS]

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

struct Options {
  std::string protocol = "wirc";
  std::string host;
  uint16_t port = wirc::kDefaultPort;
  bool portGiven = false;
  std::string device;
  std::string discoveryAddress = "255.255.255.255";
  std::string name = "wirc-cli";
  uint8_t priority = 0;
  milliseconds timeout{3000};
  // Command-specific.
  std::optional<std::string> periods, failsafe, ssid, out, country, destination, data, md5;
  bool passwordStdin = false, station = false, raw = false;
  int camera = 0, channel = 1;
  std::optional<int> frames;
  std::optional<uint16_t> toPort;
  double duration = 0;
  std::optional<int> steering, throttle;
  std::vector<std::string> positional;
  cli::PositionsOptions positions;
};

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

std::shared_ptr<wirc::TransmitterSession> login(const Options& o) {
  auto session = wirc::TransmitterSession::acquire({.host = o.host,
                                                    .port = o.port,
                                                    .device = o.device,
                                                    .discoveryAddress = o.discoveryAddress,
                                                    .transmitterName = o.name,
                                                    .priority = o.priority,
                                                    .loginTimeout = o.timeout,
                                                    .reconnect = false});
  if (!session) fail(session.error());
  if (auto error = (*session)->waitLoggedIn(o.timeout + milliseconds(500)))
    fail("cannot log in: " + *error);
  return std::move(*session);
}

// AREQ for connection `id`; the device's answer, or a timeout, decides.
int requestControl(const Options& o, uint8_t id) {
  auto session = login(o);
  std::promise<link::ControlRequestAnswered> answered;
  std::once_flag once;
  int listener = session->addListener([&](const link::LinkEvent& event) {
    if (const auto* answer = std::get_if<link::ControlRequestAnswered>(&event))
      std::call_once(once, [&] { answered.set_value(*answer); });
  });
  session->requestControlFor(id);
  auto future = answered.get_future();
  bool came = future.wait_for(o.timeout) == std::future_status::ready;
  session->removeListener(listener);
  if (!came)
    fail("no answer to the control request within " + std::to_string(o.timeout.count()) + " ms");
  auto answer = future.get();
  if (!answer.granted) fail("control request denied: " + answer.reason);
  std::printf("control right given to connection %u\n", id);
  return 0;
}

wirc::ChannelValues channelList(const std::string& text, const char* what) {
  auto channels = wirc::parseChannelList(text);
  if (!channels) usageError(std::string(what) + ": " + channels.error());
  return *channels;
}

void sendConfiguration(wirc::TransmitterSession& session, const wirc::Message& message,
                       milliseconds timeout) {
  if (auto error = wirc::validate(message)) fail(error->message());
  if (auto err = session.sendConfiguration(message, timeout))
    fail("the device refused " + wirc::commandName(err->command) + " with ERR code " +
         std::to_string(err->code) +
         (err->code == 2 ? " (denied: only the first transmitter may configure)" : ""));
}

int discover(const Options& o) {
  auto found =
      wirc::discoverDevices(o.timeout, o.host.empty() ? o.discoveryAddress : o.host, o.port);
  if (!found) fail(found.error());
  std::printf("%-21s %-24s %-8s %-5s %-5s\n", "ADDRESS", "NAME", "SERIAL", "HW", "SW");
  for (const auto& d : *found) {
    const auto& a = d.advertisement;
    std::printf("%-21s %-24s %-8s %u.%-3u %u.%u\n", d.address.toString().c_str(), a.name.c_str(),
                a.serial.c_str(), a.hardware.major, a.hardware.minor, a.software.major,
                a.software.minor);
  }
  return found->empty() ? 1 : 0;
}

int info(const Options& o) {
  auto session = login(o);
  std::this_thread::sleep_for(milliseconds(wirc::kPsdPeriodMs + 100));  // one PSD
  auto s = session->sessionStatus();
  std::printf("device        %s %s\n", s.vehicleAddress.c_str(), s.deviceName.c_str());
  std::printf("cameras       %u\n", s.cameraCount);
  std::printf("connection    %u%s\n", s.connectionId,
              s.hasControl ? " (has the control right)" : "");
  if (s.lastStatus) {
    const auto& p = *s.lastStatus;
    std::printf("battery       %.2f V\nanalog input  %.2f V\ninputs        %u %u %u %u\n",
                p.batteryMillivolts / 1000.0, p.analogMillivolts / 1000.0, p.inputs[0], p.inputs[1],
                p.inputs[2], p.inputs[3]);
  } else {
    std::printf("status        no PSD received\n");
  }
  return 0;
}

int transmitters(const Options& o) {
  auto session = login(o);
  auto list = session->listTransmitters(o.timeout);
  if (!list) fail("no transmitter list from the device");
  std::printf("%-4s %-4s %s\n", "ID", "PRIO", "NAME");
  for (const auto& t : *list)
    std::printf("%-4u %-4u %s\n", t.connectionId, t.priority, t.name.c_str());
  return 0;
}

int forwardStream(const Options& o) {
  if (o.duration <= 0) usageError("stream --to-port needs --duration S");
  auto session = login(o);
  session->startStream(static_cast<uint8_t>(o.camera), *o.toPort);
  std::fprintf(stderr, "wirc-cli: camera %d streaming to port %u for %.0f s\n", o.camera, *o.toPort,
               o.duration);
  std::this_thread::sleep_for(std::chrono::duration<double>(o.duration));
  session->stopStream(static_cast<uint8_t>(o.camera));
  return 0;
}

int stream(const Options& o) {
  if (o.toPort) return forwardStream(o);
  if (!o.out) usageError("stream needs --out FILE.mjpeg or --out DIR");
  if (!o.frames && o.duration <= 0) usageError("stream needs --frames N or --duration S");
  namespace fs = std::filesystem;
  bool toFolder = fs::is_directory(*o.out);
  std::ofstream file;
  if (!toFolder) {
    file.open(*o.out, std::ios::binary);
    if (!file) fail("cannot write '" + *o.out + "'");
  }
  auto session = login(o);
  auto cameras = session->sessionStatus().cameraCount;
  if (o.camera >= cameras)
    fail("the device has " + std::to_string(cameras) + " camera(s); use --camera 0..");
  auto socket = bindUdp(*SocketAddress::resolve("", 0));
  if (!socket) fail(socket.error());
  int size = 8 << 20;
  setsockopt(socket->get(), SOL_SOCKET, SO_RCVBUF, &size, sizeof size);
  auto device = *session->deviceAddress();
  session->startStream(static_cast<uint8_t>(o.camera), localAddress(socket->get()).port());

  wirc::StreamReceiver receiver;
  receiver.follow(device, session->status().logins);
  int saved = 0;
  auto end = std::chrono::steady_clock::now() +
             std::chrono::duration<double>(o.duration > 0 ? o.duration : 1e9);
  std::vector<uint8_t> buffer(wirc::kMaxDatagramSize);
  auto save = [&](wirc::AssembledFrame&& frame) {
    if (o.frames && saved >= *o.frames) return;
    auto bytes = frame.data.bytes();
    if (toFolder) {
      char name[32];
      std::snprintf(name, sizeof name, "frame-%06d.jpg", saved);
      std::ofstream(fs::path(*o.out) / name, std::ios::binary)
          .write(reinterpret_cast<const char*>(bytes.data()),
                 static_cast<std::streamsize>(bytes.size()));
    } else {
      file.write(reinterpret_cast<const char*>(bytes.data()),
                 static_cast<std::streamsize>(bytes.size()));
    }
    ++saved;
    receiver.recycle(std::move(frame.data));
  };
  while ((!o.frames || saved < *o.frames) && std::chrono::steady_clock::now() < end) {
    pollfd p{socket->get(), POLLIN, 0};
    if (::poll(&p, 1, 100) > 0) {
      sockaddr_in from{};
      socklen_t length = sizeof from;
      ssize_t n = ::recvfrom(socket->get(), buffer.data(), buffer.size(), 0,
                             reinterpret_cast<sockaddr*>(&from), &length);
      if (n > 0)
        receiver.push(SocketAddress(from), {buffer.data(), static_cast<size_t>(n)},
                      std::chrono::steady_clock::now(), save);
    }
    receiver.expire(std::chrono::steady_clock::now(), save);
    auto link = session->status();
    if (link.state == link::LinkState::Failed) fail("lost the device: " + link.reason);
  }
  session->stopStream(static_cast<uint8_t>(o.camera));
  auto stats = receiver.stats().assembler;
  std::fprintf(stderr, "wirc-cli: saved %d frames to %s (%llu incomplete dropped, %llu packets)\n",
               saved, o.out->c_str(), static_cast<unsigned long long>(stats.framesDropped()),
               static_cast<unsigned long long>(stats.packets));
  return saved > 0 ? 0 : 1;
}

int drive(const Options& o) {
  if (!o.steering || !o.throttle)
    usageError("drive needs --steering US and --throttle US (800..2200)");
  double seconds = std::min(o.duration > 0 ? o.duration : 1.0, 10.0);
  auto session = login(o);
  for (int i = 0; i < 50 && !session->status().hasControl; ++i)
    std::this_thread::sleep_for(milliseconds(20));
  if (!session->status().hasControl)
    fail("another transmitter has the control right (see transmitters, request-control)");
  wirc::ChannelValues pulses = wirc::neutralChannels();
  pulses[0] = static_cast<uint16_t>(*o.steering);
  pulses[1] = static_cast<uint16_t>(*o.throttle);
  auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < end) {
    session->setCommand(pulses);
    std::this_thread::sleep_for(milliseconds(50));
  }
  session->setCommand(wirc::neutralChannels());
  std::fprintf(stderr, "wirc-cli: drove %.1f s, %llu PCD sent\n", seconds,
               static_cast<unsigned long long>(session->status().commandsSent));
  return 0;
}

std::vector<uint8_t> readStdin(bool raw) {
  std::string input((std::istreambuf_iterator<char>(std::cin)), {});
  if (raw) return {input.begin(), input.end()};
  auto bytes = cli::parseHex(input);
  if (!bytes) usageError(bytes.error());
  return *bytes;
}

// EXTOUT's destinations by the names real devices use, or a number.
uint8_t destinationOf(const std::string& text) {
  static const std::map<std::string, uint8_t> names = {
      {"null", 0x00}, {"uart", 0x01}, {"spi-data", 0x81}, {"spi-command", 0x82}};
  if (auto found = names.find(text); found != names.end()) return found->second;
  return static_cast<uint8_t>(
      integer(text.c_str(), "--destination (null, uart, spi-data, spi-command or 0..255)", 0, 255));
}

int decodeCommand(const Options& o) {
  wirc::MessageStreamParser parser;
  int errors = 0;
  parser.feed(readStdin(o.raw), [&](const Expected<wirc::Message, wirc::ProtocolError>& result) {
    if (result) {
      std::cout << cli::toJson(*result).dump() << "\n";
    } else {
      ++errors;
      nlohmann::json error = {{"error", wirc::errorKindName(result.error().kind)},
                              {"command", wirc::commandName(result.error().command)},
                              {"field", result.error().field},
                              {"message", result.error().message()}};
      std::cout << error.dump() << "\n";
    }
  });
  return errors > 0 ? 1 : 0;
}

int encodeCommand(const Options& o) {
  std::string line;
  int lineNumber = 0;
  while (std::getline(std::cin, line)) {
    ++lineNumber;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    auto json = nlohmann::json::parse(line, nullptr, false);
    if (json.is_discarded()) fail("line " + std::to_string(lineNumber) + ": not JSON");
    auto message = cli::fromJson(json);
    if (!message) fail("line " + std::to_string(lineNumber) + ": " + message.error());
    auto frame = wirc::encode(*message);
    if (!frame) fail("line " + std::to_string(lineNumber) + ": " + frame.error().message());
    if (o.raw) {
      std::cout.write(reinterpret_cast<const char*>(frame->data()),
                      static_cast<std::streamsize>(frame->size()));
    } else {
      for (size_t i = 0; i < frame->size(); ++i) std::printf("%s%02X", i ? " " : "", (*frame)[i]);
      std::printf("\n");
    }
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string command = argc > 1 ? argv[1] : "help";
  if (command == "help" || command == "--help" || command == "-h") {
    std::fputs(kUsage, stdout);
    return 0;
  }
  Options o = parse(argc, argv);
  auto wantArguments = [&](size_t n) {
    if (o.positional.size() != n)
      usageError(command + " takes " + std::to_string(n) + " argument(s)");
  };
  if (command == "positions") {
    if (o.positions.dashboard.empty() || o.positions.beacons.empty())
      usageError("positions needs --marvelmind HOST:PORT and --beacon ADDR");
    o.positions.timeout = o.timeout;
    return cli::printPositions(o.positions);
  }
  if (o.protocol != "wirc") {
    cli::CousinOptions cousin{.protocol = o.protocol,
                              .host = o.host,
                              .port = static_cast<uint16_t>(o.portGiven ? o.port : 0),
                              .broadcastAddress = o.discoveryAddress,
                              .timeout = o.timeout,
                              .steering = o.steering.value_or(1500),
                              .throttle = o.throttle.value_or(1500),
                              .seconds = std::min(o.duration > 0 ? o.duration : 1.0, 10.0)};
    if (command == "drive") {
      if (!o.steering || !o.throttle)
        usageError("drive needs --steering US and --throttle US (800..2200)");
      return cli::driveCousin(cousin);
    }
    if (command == "info") return cli::infoCousin(cousin);
    if (command == "discover" && o.protocol == "btemp") return cli::discoverBtemp(cousin);
    usageError(command + " is for WiRC devices only (--protocol " + o.protocol +
               " has drive, info" + (o.protocol == "btemp" ? ", discover)" : ")"));
  }
  if (command == "discover") return discover(o);
  if (command == "info") return info(o);
  if (command == "transmitters") return transmitters(o);
  if (command == "request-control") {
    wantArguments(1);
    auto id = static_cast<uint8_t>(integer(o.positional[0].c_str(), "ID", 1, 255));
    return requestControl(o, id);
  }
  if (command == "configure") {
    if (!o.periods && !o.failsafe) usageError("configure needs --periods and/or --failsafe");
    auto session = login(o);
    if (o.periods)
      sendConfiguration(*session, wirc::Ccfg{channelList(*o.periods, "--periods")},
                        milliseconds(500));
    if (o.failsafe)
      sendConfiguration(*session, wirc::Fcfg{channelList(*o.failsafe, "--failsafe")},
                        milliseconds(500));
    return 0;
  }
  if (command == "set-name") {
    wantArguments(1);
    auto session = login(o);
    sendConfiguration(*session, wirc::Dcfg{.name = o.positional[0]}, milliseconds(500));
    std::printf("the device takes the name '%s' at its next restart\n", o.positional[0].c_str());
    return 0;
  }
  if (command == "extout") {
    if (!o.destination || !o.data) usageError("extout needs --destination D and --data HEX");
    auto data = cli::parseHex(*o.data);
    if (!data) usageError("--data: " + data.error());
    wirc::Extout message{.destination = destinationOf(*o.destination), .data = *data};
    if (auto invalid = wirc::validate(message)) usageError(invalid->message());
    auto session = login(o);
    sendConfiguration(*session, message, milliseconds(500));
    std::printf("%zu bytes sent to port 0x%02x\n", data->size(), message.destination);
    return 0;
  }
  if (command == "firmware-update") {
    if (!o.md5) usageError("firmware-update needs --md5 HEX (32 hex digits)");
    auto md5 = cli::parseHex(*o.md5);
    if (!md5 || md5->size() != 16) usageError("--md5 wants 32 hex digits");
    wirc::Fwup message;
    std::copy(md5->begin(), md5->end(), message.md5.begin());
    auto session = login(o);
    sendConfiguration(*session, message, milliseconds(500));
    std::printf("firmware update announced: the device disconnects everyone and restarts\n");
    return 0;
  }
  if (command == "wifi") {
    if (!o.ssid) usageError("wifi needs --ssid");
    // The radio's legal channels and power depend on it: no silent default.
    if (!o.country) usageError("wifi needs --country CC, the two-letter country code (e.g. HU)");
    std::string password;
    if (o.passwordStdin) std::getline(std::cin, password);
    auto session = login(o);
    sendConfiguration(*session,
                      wirc::Wcfg{.ssid = *o.ssid,
                                 .password = password,
                                 .accessPoint = !o.station,
                                 .secured = !password.empty(),
                                 .channel = static_cast<uint8_t>(o.channel),
                                 .country = *o.country},
                      milliseconds(500));
    std::printf("WiFi settings sent (password %s); they apply after the device restarts\n",
                password.empty() ? "none: open network" : "set");
    return 0;
  }
  if (command == "stream") return stream(o);
  if (command == "drive") return drive(o);
  if (command == "decode") return decodeCommand(o);
  if (command == "encode") return encodeCommand(o);
  usageError("unknown command '" + command + "'");
}
