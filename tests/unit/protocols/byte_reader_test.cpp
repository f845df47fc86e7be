#include "common/byte_reader.h"

#include <gtest/gtest.h>

#include <limits>
#include <vector>

#include "common/byte_writer.h"

namespace wircam {
namespace {

TEST(ByteReader, ReadsBigAndLittleEndian) {
  std::vector<uint8_t> data = {0x12, 0x34, 0x12, 0x34, 0x01, 0x02, 0x03, 0x04};
  ByteReader reader(data);
  EXPECT_EQ(reader.readU16Be(), 0x1234);
  EXPECT_EQ(reader.readU16Le(), 0x3412);
  EXPECT_EQ(reader.readU32Be(), 0x01020304u);
  EXPECT_TRUE(reader.ok());
  EXPECT_EQ(reader.remaining(), 0u);
}

TEST(ByteReader, FailureIsStickyAndReadsReturnZero) {
  std::vector<uint8_t> data = {0xFF, 0xFF, 0xFF};
  ByteReader reader(data);
  EXPECT_EQ(reader.readU32Be(), 0u);
  EXPECT_FALSE(reader.ok());
  EXPECT_EQ(reader.readU8(), 0u);  // a byte is there, but the reader failed
  EXPECT_EQ(reader.remaining(), 0u);
}

TEST(ByteReader, HugeLengthCannotOverflowTheBoundsCheck) {
  std::vector<uint8_t> data = {1, 2, 3};
  ByteReader reader(data);
  reader.readU8();
  EXPECT_TRUE(reader.readBytes(std::numeric_limits<size_t>::max()).empty());
  EXPECT_FALSE(reader.ok());
}

TEST(ByteReader, FixedStringStopsAtZeroAndNeverLeavesItsField) {
  std::vector<uint8_t> data = {'a', 'b', 0, 'x', 'c', 'd', 'e', 'f'};
  ByteReader reader(data);
  EXPECT_EQ(reader.readFixedString(4), "ab");
  EXPECT_EQ(reader.readFixedString(4), "cdef");  // full width, no terminator
  EXPECT_TRUE(reader.ok());
}

TEST(ByteWriter, FixedStringIsZeroPaddedAndCutAtItsWidth) {
  std::vector<uint8_t> out;
  ByteWriter writer(out);
  writer.writeFixedString("ab", 4);
  writer.writeFixedString("abcdef", 3);
  EXPECT_EQ(out, (std::vector<uint8_t>{'a', 'b', 0, 0, 'a', 'b', 'c'}));
}

}  // namespace
}  // namespace wircam
