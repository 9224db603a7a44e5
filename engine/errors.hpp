// Typed errors carrying context. Bad input (a file, a config key, a message) raises InputError;
// the app turns it into one clear line on stderr and exit status 2.
#pragma once

#include <stdexcept>
#include <string>

namespace bellows {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace bellows
