// Where H.264 can be started, from hand-made access units: an IDR, a
// non-IDR I-frame as x264 makes at a scene cut, a P-frame, cut units.
#include "common/h264_access_unit.h"

#include <gtest/gtest.h>

#include <string>

namespace wircam {
namespace {

// NAL headers: nal_ref_idc 3 and the type.
constexpr char kDelimiter = 0x09, kSps = 0x67, kPps = 0x68, kIdr = 0x65, kSlice = 0x41;
// A slice header whose slice_type is I (ue(v) 7: 0001000), for the non-IDR I.
const std::string kISliceBody("\x88\x84", 2);

// NAL units after 4-byte lengths ("avc").
std::string avc(std::initializer_list<std::string> units, size_t lengthSize = 4) {
  std::string out;
  for (const auto& unit : units) {
    for (size_t i = lengthSize; i-- > 0;) out += static_cast<char>(unit.size() >> (8 * i) & 0xff);
    out += unit;
  }
  return out;
}

std::string nal(char header, const std::string& body = "\x10\x20") {
  return std::string(1, header) + body;
}

TEST(H264AccessUnit, OnlyAnIdrIsAPlaceToStart) {
  EXPECT_TRUE(startsDecoding(avc({nal(kDelimiter), nal(kSps), nal(kPps), nal(kIdr)})));
  EXPECT_TRUE(startsDecoding(avc({nal(kIdr)})));  // sets in codec_data
  // NAL types 9, 1, 1 with slice type I: what a Foxglove client was given.
  EXPECT_FALSE(
      startsDecoding(avc({nal(kDelimiter), nal(kSlice, kISliceBody), nal(kSlice, kISliceBody)})));
  EXPECT_FALSE(startsDecoding(avc({nal(kSlice)})));
  EXPECT_FALSE(startsDecoding(""));
}

TEST(H264AccessUnit, ReadsEachLengthSizeAndAnnexB) {
  EXPECT_TRUE(startsDecoding(avc({nal(kSps), nal(kIdr)}, 2), {2}));
  EXPECT_TRUE(startsDecoding(avc({nal(kIdr)}, 1), {1}));
  EXPECT_FALSE(startsDecoding(avc({nal(kIdr)}, 2), {3}));  // no such size
  std::string annexB =
      std::string("\0\0\0\1", 4) + nal(kSps) + std::string("\0\0\1", 3) + nal(kIdr);
  EXPECT_TRUE(startsDecoding(annexB, H264Framing::byteStream()));
  std::string pOnly = std::string("\0\0\0\1", 4) + nal(kSlice);
  EXPECT_FALSE(startsDecoding(pOnly, H264Framing::byteStream()));
}

TEST(H264AccessUnit, ACutOrDamagedUnitIsNoPlaceToStart) {
  std::string whole = avc({nal(kSps), nal(kIdr)});
  EXPECT_FALSE(startsDecoding(whole.substr(0, whole.size() - 1)));  // a length past the end
  EXPECT_FALSE(startsDecoding(avc({"", nal(kIdr)})));               // an empty NAL unit
  EXPECT_FALSE(startsDecoding(std::string("\xff\xff\xff\xff", 4) + nal(kIdr)));
}

}  // namespace
}  // namespace wircam
