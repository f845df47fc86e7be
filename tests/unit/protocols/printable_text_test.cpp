#include "common/printable_text.h"

#include <gtest/gtest.h>

namespace wircam {
namespace {

TEST(PrintableText, KeepsUtf8AsItIs) {
  EXPECT_EQ(printableText("P\xC3\xA1l\xE2\x80\x99s iPhone"), "Pál’s iPhone");
}

TEST(PrintableText, ReadsOtherBytesAsLatin1) { EXPECT_EQ(printableText("P\xE1l"), "Pál"); }

TEST(PrintableText, EscapesC0ControlsAndDel) {
  EXPECT_EQ(printableText("a\nb\rc\x1B[31md\x07\x7F"), "a\\x0Ab\\x0Dc\\x1B[31md\\x07\\x7F");
}

TEST(PrintableText, EscapesC1ControlsReadAsLatin1) {
  // 0x9B alone is CSI to a terminal that reads Latin-1 or C1 as such.
  EXPECT_EQ(printableText("a\x9B"
                          "31mb\x92"),
            "a\\x9B31mb\\x92");
}

TEST(PrintableText, EscapesC1ControlsEncodedAsUtf8) {
  EXPECT_EQ(printableText("a\xC2\x9B"
                          "31m\xC2\x85z"),
            "a\\x9B31m\\x85z");
  // U+00A0 and above are text.
  EXPECT_EQ(printableText("\xC2\xA0\xC2\xB0"), "\xC2\xA0\xC2\xB0");
}

TEST(PrintableText, AZeroByteDoesNotCutTheTextShort) {
  EXPECT_EQ(printableText(std::string_view("ON\0OFF", 6)), "ON\\x00OFF");
}

TEST(PrintableText, ANewlineCannotForgeALogLine) {
  std::string shown = printableText("x\nwirc-recorder: FORGED LINE");
  EXPECT_EQ(shown.find('\n'), std::string::npos);
  EXPECT_EQ(shown, "x\\x0Awirc-recorder: FORGED LINE");
}

}  // namespace
}  // namespace wircam
