#include "foxglove/annex_b.h"

#include <gtest/gtest.h>

namespace wircam::recorder {
namespace {

using namespace std::string_literals;

// An avcC record: version 1, Main profile, 4-byte lengths, one SPS, one PPS.
const std::string kRecord = "\x01\x4d\x00\x1f\xff\xe1\x00\x03\x67\x4d\x1f\x01\x00\x02\x68\xee"s;
const std::string kStart = "\0\0\0\1"s;
const std::string kSets = kStart + "\x67\x4d\x1f" + kStart + "\x68\xee";

TEST(AnnexB, AnIdrGetsItsParameterSetsAndEachNalUnitAStartCode) {
  auto converter = AnnexB::fromAvcC(kRecord);
  ASSERT_TRUE(converter);
  std::string frame = "\0\0\0\2\x65\x88"s + "\0\0\0\1\x06"s;
  EXPECT_EQ(converter->convert(frame), kSets + kStart + "\x65\x88" + kStart + "\x06");
  // Not a key frame: as it is.
  EXPECT_EQ(converter->convert("\0\0\0\1\x41"s), kStart + "\x41");
}

TEST(AnnexB, TheParameterSetsFollowTheDelimiterAndAreNotRepeated) {
  auto converter = AnnexB::fromAvcC(kRecord);
  ASSERT_TRUE(converter);
  // An access unit delimiter (9) stays first.
  EXPECT_EQ(converter->convert("\0\0\0\2\x09\xf0"s + "\0\0\0\1\x65"s),
            kStart + "\x09\xf0" + kSets + kStart + "\x65");
  // An encoder that repeats them in the stream (x264 does): not twice.
  EXPECT_EQ(converter->convert("\0\0\0\1\x67"s + "\0\0\0\1\x68"s + "\0\0\0\1\x65"s),
            kStart + "\x67" + kStart + "\x68" + kStart + "\x65");
}

TEST(AnnexB, TwoByteLengthsAreReadAsTheRecordSays) {
  std::string record = kRecord;
  record[4] = '\xfd';  // lengthSizeMinusOne = 1
  auto converter = AnnexB::fromAvcC(record);
  ASSERT_TRUE(converter);
  EXPECT_EQ(converter->convert("\0\2\x41\x9a"s), kStart + "\x41\x9a");
}

TEST(AnnexB, ALengthPastTheEndIsRefused) {
  auto converter = AnnexB::fromAvcC(kRecord);
  ASSERT_TRUE(converter);
  EXPECT_FALSE(converter->convert("\0\0\0\x09\x41"s));
  EXPECT_FALSE(converter->convert("\0\0"s));
  EXPECT_EQ(converter->convert(""), "");
}

TEST(AnnexB, WhatIsNotAnAvcCRecordIsRefused) {
  EXPECT_FALSE(AnnexB::fromAvcC(""));
  EXPECT_FALSE(AnnexB::fromAvcC("\0\0\0\1\x67\x4d\x1f"s));  // Annex B, not avcC
  EXPECT_FALSE(AnnexB::fromAvcC(kRecord.substr(0, 10)));    // the SPS cut short
  EXPECT_FALSE(AnnexB::fromAvcC(kRecord.substr(0, 13)));    // no PPS length
}

}  // namespace
}  // namespace wircam::recorder
