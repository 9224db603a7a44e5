// The SHA-256 digest a manifest records of each file it lists (libsodium), so that a file changed
// after it was saved (edited by hand, swapped, corrupted) is noticed when the session is read.
// It detects changes, not forgery: whoever can rewrite a file can rewrite the manifest too.
#pragma once

#include <string>
#include <string_view>

namespace bellows {

/// 64 lowercase hex digits.
std::string sha256_hex(std::string_view bytes);

/// True for 64 lowercase hex digits, the form sha256_hex() writes.
bool is_sha256_hex(std::string_view text);

}  // namespace bellows
