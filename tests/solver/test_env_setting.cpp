// The solvers' environment variables (sim/core/env_setting.h): a value set but not
// understood is refused naming the variable; unset or empty is the default.
#include <gtest/gtest.h>

#include <cstdlib>

#include "sim/core/env_setting.h"

using namespace softtled;

namespace {
const char* kName = "SOFTTLED_TEST_ENV_SETTING";

int int_of(const char* value) {
  ::setenv(kName, value, 1);
  return env_int(kName, 16, 1, 1024);
}
bool switch_of(const char* value) {
  ::setenv(kName, value, 1);
  return env_switch(kName, true);
}
}  // namespace

TEST(EnvSetting, WholeNumbersInRangeOnly) {
  ::unsetenv(kName);
  EXPECT_EQ(env_int(kName, 16, 1, 1024), 16);
  EXPECT_EQ(int_of(""), 16);
  EXPECT_EQ(int_of("32"), 32);
  EXPECT_EQ(int_of("1024"), 1024);
  // atoi read "1e9" as 1 and "abc" as 0; each is now an error naming the variable.
  for (const char* bad : {"1e9", "abc", " 5", "5 ", "0", "1025", "-3", "99999999999999999999", "0x10", "8.0"}) {
    try {
      int_of(bad);
      ADD_FAILURE() << "'" << bad << "' was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string(kName) + "="), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("expected a whole number in [1, 1024]"), std::string::npos) << e.what();
    }
  }
  ::unsetenv(kName);
}

TEST(EnvSetting, SwitchesAreZeroOrOne) {
  ::unsetenv(kName);
  EXPECT_TRUE(env_switch(kName, true));
  EXPECT_FALSE(env_switch(kName, false));
  EXPECT_TRUE(switch_of(""));
  EXPECT_FALSE(switch_of("0"));
  EXPECT_TRUE(switch_of("1"));
  // "off" kept the SIMD path on (only "0" turned it off).
  for (const char* bad : {"off", "false", "no", "00", " 0", "2"})
    EXPECT_THROW(switch_of(bad), InputError) << "'" << bad << "'";
  ::unsetenv(kName);
}
