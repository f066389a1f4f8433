#pragma once
// Expected failures travel as values: std::expected<T, Error>. Exceptions are kept for
// broken invariants and never cross a thread boundary.
#include <expected>
#include <string>

namespace covtrack {

struct Error {
  std::string message;  // says what failed and where (file:line, device, byte offset)
};

template <typename T>
using Result = std::expected<T, Error>;

inline std::unexpected<Error> fail(std::string message) {
  return std::unexpected<Error>(Error{std::move(message)});
}

}  // namespace covtrack
