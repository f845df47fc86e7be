// wirc-cli's commands for a WiRC device: each logs in as a transmitter
// (but decode and encode, which only translate), does its work, prints
// what came of it and returns the exit code.
#include "wirc_commands.h"

#include <poll.h>
#include <sys/socket.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <future>
#include <iostream>
#include <map>
#include <mutex>
#include <sstream>
#include <thread>

#include "hex.h"
#include "message_json.h"
#include "wirc/channel_list.h"
#include "wirc/discovery.h"
#include "wirc/message_stream_parser.h"
#include "wirc/stream_receiver.h"
#include "wirc/transmitter_session.h"

namespace wircam::cli {

using std::chrono::milliseconds;

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
int requestControlFor(const Options& o, uint8_t id) {
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
  if (!answer.granted) {
    // The device's denial has no reason field: a connection nobody holds
    // is told apart from one the priorities keep, by the device's list.
    auto list = session->listTransmitters(o.timeout);
    if (list && std::none_of(list->begin(), list->end(),
                             [id](const auto& t) { return t.connectionId == id; }))
      fail("control request denied: no transmitter is logged in as connection " +
           std::to_string(id) + " (wirc-cli transmitters lists them)");
    fail("control request denied: " + answer.reason);
  }
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
  auto session = login(o);
  auto cameras = session->sessionStatus().cameraCount;
  if (o.camera >= cameras)
    fail("the device has " + std::to_string(cameras) +
         (cameras == 1 ? " camera: --camera 0"
                       : " cameras: --camera 0.." + std::to_string(cameras - 1)));
  // Made once there is something to write into it: a refusal leaves no
  // empty file behind.
  bool toFolder = fs::is_directory(*o.out);
  std::ofstream file;
  if (!toFolder) {
    file.open(*o.out, std::ios::binary);
    if (!file) fail("cannot write '" + *o.out + "'");
  }
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

int decode(const Options& o) {
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
  // Bytes that were no message (skipped before a frame's start) or the
  // start of one the input cut off: said as errors too, not passed over.
  auto sayLeftOver = [&](const char* kind, size_t bytes, const std::string& message) {
    ++errors;
    std::cout << nlohmann::json{{"error", kind}, {"bytes", bytes}, {"message", message}}.dump()
              << "\n";
  };
  if (auto skipped = parser.stats().garbageBytes)
    sayLeftOver("garbage", skipped,
                std::to_string(skipped) + " bytes were no message (no AA BB before them)");
  if (auto cut = parser.pendingBytes())
    sayLeftOver("truncated", cut,
                "the input ends " + std::to_string(cut) + " bytes into a message");
  return errors > 0 ? 1 : 0;
}

int encode(const Options& o) {
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

int requestControl(const Options& o) {
  auto id = static_cast<uint8_t>(integer(o.positional[0].c_str(), "ID", 1, 255));
  return requestControlFor(o, id);
}

int configure(const Options& o) {
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

int setName(const Options& o) {
  wirc::Dcfg message{.name = o.positional[0]};
  // Refused before the login: what the device would refuse is a usage error.
  if (auto invalid = wirc::validate(message)) usageError(invalid->message());
  auto session = login(o);
  sendConfiguration(*session, message, milliseconds(500));
  std::printf("the device takes the name '%s' at its next restart\n", o.positional[0].c_str());
  return 0;
}

int extout(const Options& o) {
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

int firmwareUpdate(const Options& o) {
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

int wifi(const Options& o) {
  if (!o.ssid) usageError("wifi needs --ssid");
  // The radio's legal channels and power depend on it: no silent default.
  if (!o.country) usageError("wifi needs --country CC, the two-letter country code (e.g. HU)");
  // (The protocol's field is "2 characters and a zero byte"; codes are letters.)
  bool twoLetters =
      o.country->size() == 2 && std::all_of(o.country->begin(), o.country->end(),
                                            [](unsigned char c) { return std::isalpha(c) != 0; });
  if (!twoLetters)
    usageError("--country wants a two-letter country code (e.g. HU), not '" + *o.country + "'");
  std::string password;
  if (o.passwordStdin) std::getline(std::cin, password);
  wirc::Wcfg message{.ssid = *o.ssid,
                     .password = password,
                     .accessPoint = !o.station,
                     .secured = !password.empty(),
                     .channel = static_cast<uint8_t>(o.channel),
                     .country = *o.country};
  if (auto invalid = wirc::validate(message)) usageError(invalid->message());
  auto session = login(o);
  sendConfiguration(*session, message, milliseconds(500));
  std::printf("WiFi settings sent (password %s); they apply after the device restarts\n",
              password.empty() ? "none: open network" : "set");
  return 0;
}

}  // namespace wircam::cli
