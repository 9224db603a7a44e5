// Key codes the console understands, independent of ncurses: printable characters are themselves;
// special keys have codes above the character range. The terminal layer translates.
#pragma once

namespace bellows::ui::key {

inline constexpr int kNone = -1;
inline constexpr int kSpecial = 0x110000;  // above every Unicode code point
inline constexpr int kEnter = kSpecial + 1;
inline constexpr int kEscape = kSpecial + 2;
inline constexpr int kUp = kSpecial + 3;
inline constexpr int kDown = kSpecial + 4;
inline constexpr int kLeft = kSpecial + 5;
inline constexpr int kRight = kSpecial + 6;
inline constexpr int kPageUp = kSpecial + 7;
inline constexpr int kPageDown = kSpecial + 8;
inline constexpr int kHome = kSpecial + 9;
inline constexpr int kEnd = kSpecial + 10;
inline constexpr int kBackspace = kSpecial + 11;
inline constexpr int kF1 = kSpecial + 12;
inline constexpr int kResize = kSpecial + 13;
inline constexpr int kTab = kSpecial + 14;
inline constexpr int kOther = kSpecial + 15;  // a function key the console has no use for
inline constexpr int kClearLine = 0x15;       // Ctrl-U: clears a prompt's field
inline constexpr int kRepaint = 0x0c;         // Ctrl-L: repaints the whole screen

}  // namespace bellows::ui::key
