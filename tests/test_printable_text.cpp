// printable(): text from outside made safe for a terminal, escaped and shortened.
#include <gtest/gtest.h>

#include "engine/base/printable_text.hpp"

namespace bellows {
namespace {

TEST(PrintableText, KeepsPlainTextAndPrintableUtf8) {
  EXPECT_EQ(printable("session 2024-05-01_12-00-00_paper"), "session 2024-05-01_12-00-00_paper");
  EXPECT_EQ(printable("30 \xc2\xb0, caf\xc3\xa9, \xe6\xbc\xa2\xe5\xad\x97, \xf0\x9f\x98\x80"),
            "30 \xc2\xb0, caf\xc3\xa9, \xe6\xbc\xa2\xe5\xad\x97, \xf0\x9f\x98\x80");
  EXPECT_EQ(printable(""), "");
}

TEST(PrintableText, EscapesEveryControl) {
  EXPECT_EQ(printable("a\x1b]0;title\x07z"), "a\\e]0;title\\x07z");
  EXPECT_EQ(printable("line\nnext\r\ttab\x7f"), "line\\nnext\\r\\ttab\\x7f");
  EXPECT_EQ(printable(std::string("nul\0x", 5)), "nul\\x00x");
  EXPECT_EQ(printable("\xc2\x9b"
                      "31m"),
            "\\u{009b}31m");  // C1 CSI as UTF-8
  EXPECT_EQ(printable("abc\xe2\x80\xae"
                      "cba"),
            "abc\\u{202e}cba");  // right-to-left override
  EXPECT_EQ(printable("\xef\xbb\xbf"
                      "time_s"),
            "\\u{feff}time_s");  // a byte order mark, made visible
}

TEST(PrintableText, EscapesInvalidUtf8ByteByByte) {
  EXPECT_EQ(printable("\xff\xfe"), "\\xff\\xfe");
  EXPECT_EQ(printable("\xc0\xaf"), "\\xc0\\xaf");           // overlong '/'
  EXPECT_EQ(printable("\xed\xa0\x80"), "\\xed\\xa0\\x80");  // a surrogate
  EXPECT_EQ(printable("cut \xe2\x82"), "cut \\xe2\\x82");   // a sequence cut short
  EXPECT_EQ(printable("\x9b[2J"), "\\x9b[2J");              // a raw 8-bit CSI
}

TEST(PrintableText, ShortensLongTextAtACharacter) {
  const std::string long_text(10 << 20, 'x');
  const std::string shown = printable(long_text, 100);
  EXPECT_EQ(shown, std::string(100, 'x') + "... (10485760 bytes)");
  // An escape is never cut in half.
  EXPECT_EQ(printable("abc\x1b", 4), "abc... (4 bytes)");
  EXPECT_EQ(printable("ab\xc3\xa9", 3), "ab... (4 bytes)");
  EXPECT_EQ(printable(std::string(200, 'y')), std::string(200, 'y'));  // kPrintableField fits exactly
}

}  // namespace
}  // namespace bellows
