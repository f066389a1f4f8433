#pragma once
// The readers' tests check that an error message names what and where: this part of it.
#include <string>

#include <gtest/gtest.h>

namespace covtrack::testing {

inline void expect_has(const std::string& msg, const std::string& part) {
  EXPECT_NE(msg.find(part), std::string::npos) << "'" << part << "' not in: " << msg;
}

}  // namespace covtrack::testing
