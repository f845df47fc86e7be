#include "wirc/messages.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace wircam::wirc {
namespace {

Bytes hex(std::initializer_list<int> values) { return Bytes(values.begin(), values.end()); }

ChannelValues filled(uint16_t value) {
  ChannelValues values{};
  values.fill(value);
  return values;
}

template <typename T>
T roundTrip(const T& message) {
  auto frame = encode(message);
  EXPECT_TRUE(frame.has_value()) << frame.error().message();
  auto decoded = decode(*frame);
  EXPECT_TRUE(decoded.has_value()) << decoded.error().message();
  return std::get<T>(*decoded);
}

ProtocolError encodeError(const Message& message) {
  auto frame = encode(message);
  EXPECT_FALSE(frame.has_value());
  return frame.has_value() ? ProtocolError{} : frame.error();
}

ProtocolError decodeError(uint8_t command, const Bytes& body) {
  auto decoded = decode(frameRaw(command, body));
  EXPECT_FALSE(decoded.has_value());
  return decoded.has_value() ? ProtocolError{} : decoded.error();
}

TEST(Messages, SpecExampleDecodesAsWst) {
  auto decoded = decode(hex({0xAA, 0xBB, 0x1A, 0x04, 0x01, 0x01, 0x01, 0x00, 0x67, 0x35}));
  ASSERT_TRUE(decoded.has_value()) << decoded.error().message();
  auto wst = std::get<Wst>(*decoded);
  EXPECT_EQ(wst.connectionId, 1);
  EXPECT_EQ(wst.cameraCount, 1);
  EXPECT_EQ(wst.controlPort, 0x0100);
}

TEST(Messages, SpecExampleIsWhatWstEncodesTo) {
  auto frame = encode(Wst{.connectionId = 1, .cameraCount = 1, .controlPort = 0x0100});
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(*frame, hex({0xAA, 0xBB, 0x1A, 0x04, 0x01, 0x01, 0x01, 0x00, 0x67, 0x35}));
}

TEST(Messages, EveryMessageRoundTrips) {
  ChannelValues pulses{};
  for (size_t i = 0; i < kChannelCount; ++i) pulses[i] = static_cast<uint16_t>(800 + 100 * i);
  ChannelValues periods = filled(20000);
  periods[0] = periods[1] = 5000;
  ChannelValues failsafe = pulses;
  failsafe[3] = kFailsafeConstantLevel;
  failsafe[4] = kFailsafeHoldLast;

  EXPECT_EQ(roundTrip(Bcsd{.system = 2, .version = {1, 3}}), (Bcsd{2, {1, 3}}));
  Bcsa bcsa{
      .hardware = {2, 1}, .software = {1, 30}, .name = std::string(64, 'n'), .serial = "SN12345"};
  EXPECT_EQ(roundTrip(bcsa), bcsa);
  Tl tl{.system = 0, .version = {0, 1}, .priority = 200, .name = "wircam", .statusPort = 50123};
  EXPECT_EQ(roundTrip(tl), tl);
  Dcfg dcfg{.name = "rover", .cameraOffMillivolts = 6500, .deviceOffMillivolts = 6000};
  EXPECT_EQ(roundTrip(dcfg), dcfg);
  EXPECT_EQ(roundTrip(Ccfg{periods}), Ccfg{periods});
  EXPECT_EQ(roundTrip(Fcfg{failsafe}), Fcfg{failsafe});
  EXPECT_EQ(roundTrip(Pcd{pulses}), Pcd{pulses});
  Psd psd{.batteryMillivolts = 7400, .analogMillivolts = 1234, .inputs = {1, 0, 1, 0}};
  EXPECT_EQ(roundTrip(psd), psd);
  Wcfg wcfg{.ssid = "Dension WiRC",
            .password = "secret",
            .accessPoint = false,
            .secured = true,
            .channel = 11,
            .country = "HU"};
  EXPECT_EQ(roundTrip(wcfg), wcfg);
  EXPECT_EQ(roundTrip(Tlr{}), Tlr{});
  Tlst tlst{.connectionId = 3, .priority = 9, .name = "phone"};
  EXPECT_EQ(roundTrip(tlst), tlst);
  EXPECT_EQ(roundTrip(Tlend{}), Tlend{});
  EXPECT_EQ(roundTrip(Areq{.connectionId = 7}), Areq{7});
  Agr agr{
      .connectionId = 2, .priority = 5, .name = "pc", .notification = AccessNotification::Revoked};
  EXPECT_EQ(roundTrip(agr), agr);
  Fwup fwup;
  for (size_t i = 0; i < fwup.md5.size(); ++i) fwup.md5[i] = static_cast<uint8_t>(0xF0 + i);
  EXPECT_EQ(roundTrip(fwup), fwup);
  EXPECT_EQ(roundTrip(Stst{.camera = 1, .port = 5000}), (Stst{1, 5000}));
  EXPECT_EQ(roundTrip(Est{.camera = 1}), Est{1});
  Extout extout{.destination = 1, .data = Bytes(254, 0x55)};
  EXPECT_EQ(roundTrip(extout), extout);
  EXPECT_EQ(roundTrip(Extout{.destination = 4, .data = {}}), (Extout{4, {}}));
  EXPECT_EQ(roundTrip(Err{.command = 0x13, .code = 1}), (Err{0x13, 1}));
}

TEST(Messages, BodyLengthsMatchTheSpec) {
  struct Case {
    Message message;
    size_t length;
  };
  std::vector<Case> cases = {
      {Bcsd{}, 3},
      {Bcsa{}, 75},
      {Tl{}, 70},
      {Dcfg{}, 68},
      {Ccfg{filled(10000)}, 24},
      {Fcfg{filled(1500)}, 24},
      {Wst{}, 4},
      {Pcd{filled(1500)}, 24},
      {Psd{}, 8},
      {Wcfg{}, 102},
      {Tlr{}, 0},
      {Tlst{}, 66},
      {Tlend{}, 0},
      {Areq{}, 1},
      {Agr{}, 67},
      {Fwup{}, 16},
      {Stst{}, 3},
      {Est{}, 1},
      {Err{}, 3},
  };
  for (const auto& c : cases) {
    auto frame = encode(c.message);
    ASSERT_TRUE(frame.has_value()) << commandName(commandCode(c.message));
    EXPECT_EQ((*frame)[3], c.length) << commandName(commandCode(c.message));
    EXPECT_EQ(frame->size(), c.length + kHeaderSize + kCrcSize);
  }
}

TEST(Messages, RejectsABodyOfTheWrongLengthForEachCommand) {
  for (uint8_t command : {0x01, 0x02, 0x11, 0x12, 0x13, 0x14, 0x1A, 0x21, 0x22, 0x31, 0x32, 0x33,
                          0x34, 0x35, 0x36, 0x37, 0x41, 0x42, 0xFF}) {
    auto good = decodeBody(command, Bytes(0));
    size_t wrong = good.has_value() ? 1 : 254;  // TLR/TLEND are empty: one byte is wrong
    auto error = decodeError(command, Bytes(wrong, 0));
    EXPECT_EQ(error.kind, ErrorKind::BadLength) << commandName(command);
    EXPECT_EQ(error.command, command);
  }
  EXPECT_EQ(decodeError(0x50, Bytes{}).kind, ErrorKind::BadLength);  // EXTOUT needs a destination
}

TEST(Messages, RejectsCcfgPeriodOutsideTheRangeNamingTheChannel) {
  ChannelValues periods = filled(10000);
  periods[2] = periods[3] = 4999;
  auto error = encodeError(Ccfg{periods});
  EXPECT_EQ(error.kind, ErrorKind::InvalidField);
  EXPECT_EQ(error.command, 0x13);
  EXPECT_EQ(error.field, "ch3 period");

  periods[2] = periods[3] = 20001;
  EXPECT_EQ(encodeError(Ccfg{periods}).field, "ch3 period");
}

TEST(Messages, RejectsCcfgWithUnequalChannelPairs) {
  for (size_t pair = 0; pair < 3; ++pair) {
    ChannelValues periods = filled(10000);
    periods[2 * pair + 1] = 12000;
    auto error = encodeError(Ccfg{periods});
    EXPECT_EQ(error.field, "ch" + std::to_string(2 * pair + 2) + " period");
  }
}

TEST(Messages, CcfgIgnoresTheUnusedChannels) {
  ChannelValues periods = filled(10000);
  for (size_t i = 6; i < kChannelCount; ++i) periods[i] = 0;
  EXPECT_TRUE(encode(Ccfg{periods}).has_value());
}

TEST(Messages, CcfgRulesAlsoApplyWhenDecoding) {
  ChannelValues periods = filled(10000);
  periods[0] = 3000;
  Bytes body;
  for (uint16_t p : periods) {
    body.push_back(static_cast<uint8_t>(p >> 8));
    body.push_back(static_cast<uint8_t>(p));
  }
  auto error = decodeError(0x13, body);
  EXPECT_EQ(error.kind, ErrorKind::InvalidField);
  EXPECT_EQ(error.field, "ch1 period");
}

TEST(Messages, FcfgAcceptsPulsesAndTheTwoSpecialValuesOnly) {
  for (uint16_t ok : {800, 1500, 2200, 0x0000, 0xFFFF})
    EXPECT_TRUE(encode(Fcfg{filled(ok)}).has_value()) << ok;
  for (uint16_t bad : {1, 799, 2201, 0xFFFE}) {
    ChannelValues values = filled(1500);
    values[11] = bad;
    EXPECT_EQ(encodeError(Fcfg{values}).field, "ch12 failsafe") << bad;
  }
}

TEST(Messages, PcdOutOfRangeNeverEncodes) {
  for (uint16_t bad : {0, 799, 2201, 0xFFFF}) {
    ChannelValues values = filled(1500);
    values[1] = bad;
    auto error = encodeError(Pcd{values});
    EXPECT_EQ(error.field, "ch2 value") << bad;
    EXPECT_EQ(error.command, 0x21);
  }
  EXPECT_TRUE(encode(Pcd{filled(800)}).has_value());
  EXPECT_TRUE(encode(Pcd{filled(2200)}).has_value());
}

TEST(Messages, PcdOutOfRangeIsRejectedWhenDecoding) {
  Bytes body(24, 0);  // all channels 0 µs
  EXPECT_EQ(decodeError(0x21, body).field, "ch1 value");
}

TEST(Messages, TextLongerThanItsFieldIsRefusedNotTruncated) {
  EXPECT_EQ(encodeError(Tl{.name = std::string(65, 'x')}).field, "name");
  EXPECT_TRUE(encode(Tl{.name = std::string(64, 'x')}).has_value());
  EXPECT_EQ(encodeError(Bcsa{.serial = "12345678"}).field, "serial");
  EXPECT_EQ(encodeError(Wcfg{.ssid = std::string(33, 's')}).field, "ssid");
  EXPECT_EQ(encodeError(Wcfg{.password = std::string(65, 'p')}).field, "password");
  EXPECT_EQ(encodeError(Wcfg{.country = "HUN"}).field, "country");  // 2 letters + zero byte
}

TEST(Messages, TextWithZeroOrControlBytesIsRefused) {
  EXPECT_EQ(encodeError(Tl{.name = std::string("a\0b", 3)}).field, "name");
  EXPECT_EQ(encodeError(Dcfg{.name = "line\nbreak"}).field, "name");
}

TEST(Messages, PasswordErrorsNeverQuoteThePassword) {
  auto error = encodeError(Wcfg{.password = std::string(70, 'q')});
  EXPECT_EQ(error.message().find("qqq"), std::string::npos);
}

TEST(Messages, FullWidthTextWithoutTerminatorDecodes) {
  Bytes body(70, 'z');
  body[0] = 0;      // sys
  body[3] = 1;      // prio
  body[68] = 0x13;  // status port
  body[69] = 0x88;
  auto decoded = decode(frameRaw(0x11, body));
  ASSERT_TRUE(decoded.has_value());
  auto tl = std::get<Tl>(*decoded);
  EXPECT_EQ(tl.name, std::string(64, 'z'));
  EXPECT_EQ(tl.statusPort, 5000);
}

TEST(Messages, AgrNotificationMustBeKnown) {
  Bytes body(67, 0);
  body[66] = 4;
  EXPECT_EQ(decodeError(0x36, body).field, "notif");
}

TEST(Messages, ExtoutDataIsLimitedTo254Bytes) {
  EXPECT_EQ(encodeError(Extout{.destination = 0, .data = Bytes(255, 1)}).field, "data");
}

TEST(Messages, UnknownCommandWithValidCrcIsNamed) {
  auto error = decodeError(0x5A, Bytes{1, 2, 3});
  EXPECT_EQ(error.kind, ErrorKind::UnknownCommand);
  EXPECT_EQ(error.command, 0x5A);
  EXPECT_NE(error.message().find("0x5A"), std::string::npos);
}

TEST(Messages, BadCrcIsDetected) {
  auto frame = *encode(Stst{.camera = 0, .port = 5000});
  frame.back() ^= 0x01;
  auto decoded = decode(frame);
  ASSERT_FALSE(decoded.has_value());
  EXPECT_EQ(decoded.error().kind, ErrorKind::BadCrc);
}

TEST(Messages, CorruptedBodyFailsTheCrc) {
  auto frame = *encode(Pcd{filled(1500)});
  frame[6] ^= 0x40;
  EXPECT_EQ(decode(frame).error().kind, ErrorKind::BadCrc);
}

TEST(Messages, TruncatedOrOverlongFramesAreRejected) {
  auto frame = *encode(Est{.camera = 0});
  for (size_t size = 0; size < frame.size(); ++size) {
    auto decoded = decode(std::span(frame).first(size));
    EXPECT_FALSE(decoded.has_value()) << size;
  }
  frame.push_back(0);
  EXPECT_FALSE(decode(frame).has_value());
}

// An AGR (or TLST) whose name field holds these raw bytes.
Bytes agrNamed(const std::string& raw) {
  Bytes body(1 + 1 + 64 + 1, 0);  // ID, priority, name, notification
  body[0] = 1;
  body[1] = 5;
  std::copy(raw.begin(), raw.end(), body.begin() + 2);
  body.back() = static_cast<uint8_t>(AccessNotification::Revoked);
  return frameRaw(static_cast<uint8_t>(Command::Agr), body);
}

TEST(Messages, ReceivedUtf8NamesAreKeptAsTheyAre) {
  auto decoded = decode(agrNamed("P\xC3\xA1l\xE2\x80\x99s iPhone"));
  ASSERT_TRUE(decoded.has_value()) << decoded.error().message();
  EXPECT_EQ(std::get<Agr>(*decoded).name, "Pál’s iPhone");
}

TEST(Messages, ReceivedLatin1NamesAreShownAsUtf8) {
  auto decoded = decode(agrNamed("P\xE1l"));
  ASSERT_TRUE(decoded.has_value()) << decoded.error().message();
  EXPECT_EQ(std::get<Agr>(*decoded).name, "Pál");
}

TEST(Messages, ControlCharactersInReceivedTextAreEscaped) {
  auto decoded = decode(agrNamed("bell\x07"));
  ASSERT_TRUE(decoded.has_value()) << decoded.error().message();
  EXPECT_EQ(std::get<Agr>(*decoded).name, "bell\\x07");
}

TEST(Messages, C1ControlCharactersInReceivedTextAreEscaped) {
  // CSI (0x9B) and 0x92, as a TLST name: wirc-cli prints these names.
  auto decoded =
      decode(agrNamed("csi\x9B"
                      "2Jx\x92"));
  ASSERT_TRUE(decoded.has_value()) << decoded.error().message();
  EXPECT_EQ(std::get<Agr>(*decoded).name, "csi\\x9B2Jx\\x92");
}

TEST(Messages, ReceivedTextEndsAtItsFirstZeroByte) {
  auto decoded = decode(agrNamed(std::string("short\0garbage", 13)));
  ASSERT_TRUE(decoded.has_value());
  EXPECT_EQ(std::get<Agr>(*decoded).name, "short");
}

TEST(Messages, EncodingTextStaysPrintableAscii) {
  auto encoded = encode(Tl{.name = "Pál"});
  ASSERT_FALSE(encoded.has_value());
  EXPECT_NE(encoded.error().message().find("printable ASCII"), std::string::npos);
}

TEST(Messages, CommandNamesCoverTheSpec) {
  // Every message of WiRC v1.3 by its code, as the spec names it.
  const std::pair<uint8_t, const char*> spec[] = {
      {0x01, "BCSD"}, {0x02, "BCSA"}, {0x11, "TL"},    {0x12, "DCFG"},   {0x13, "CCFG"},
      {0x14, "FCFG"}, {0x1A, "WST"},  {0x21, "PCD"},   {0x22, "PSD"},    {0x31, "WCFG"},
      {0x32, "TLR"},  {0x33, "TLST"}, {0x34, "TLEND"}, {0x35, "AREQ"},   {0x36, "AGR"},
      {0x37, "FWUP"}, {0x41, "STST"}, {0x42, "EST"},   {0x50, "EXTOUT"}, {0xFF, "ERR"}};
  for (auto [code, name] : spec) EXPECT_EQ(commandName(code), name) << int(code);
  EXPECT_EQ(std::size(spec), std::variant_size_v<Message>);
  EXPECT_EQ(commandName(0x99), "0x99");
}

}  // namespace
}  // namespace wircam::wirc
