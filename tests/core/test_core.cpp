#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <ctime>
#include <string>
#include <utility>
#include <vector>
#include <thread>

#include "drape/core/error.hpp"
#include "drape/core/isolate.hpp"
#include "drape/core/math.hpp"
#include "drape/core/timecode.hpp"

namespace drape {
namespace {

TEST(TimeCode, PrintsSmpte) {
  EXPECT_EQ((TimeCode{0, 30}).smpte(), "00:00:00:00");
  EXPECT_EQ((TimeCode{29, 30}).smpte(), "00:00:00:29");
  EXPECT_EQ((TimeCode{30 * 3661 + 7, 30}).smpte(), "01:01:01:07");
  EXPECT_EQ((TimeCode{25 * 60, 25}).smpte(), "00:01:00:00");
  EXPECT_EQ((TimeCode{-31, 30}).smpte(), "-00:00:01:01");  // a studio's lead-in, before the take's start
}

TEST(TimeCode, ParsesWhatItPrints) {
  for (std::int64_t f : {0, 1, 29, 30, 1799, 108000 + 17, -1, -31, -108000 - 17}) {
    const TimeCode tc{f, 30};
    EXPECT_EQ(TimeCode::parseSmpte(tc.smpte(), 30).frame, f);
  }
  EXPECT_THROW((void)TimeCode::parseSmpte("00:00:00:30", 30), Error);
  EXPECT_THROW((void)TimeCode::parseSmpte("1:2:3", 30), Error);
  EXPECT_THROW((void)TimeCode::parseSmpte("--00:00:01:00", 30), Error);
  EXPECT_THROW((void)TimeCode::parseSmpte("-+0:00:01:00", 30), Error);
  EXPECT_THROW((void)TimeCode::parseSmpte("00:00:01:00 ", 30), Error);
}

TEST(TimeCode, ReadsTheTimeOfDayInTheLocalZone) {
  const char* saved = std::getenv("TZ");
  const std::string before = saved != nullptr ? saved : "";
  // POSIX zones: XYZ-5 is five hours ahead of UTC, ABC+3:30 three and a half behind.
  const std::vector<std::pair<const char*, long>> zones = {{"UTC0", 0}, {"XYZ-5", 5 * 3600}, {"ABC+3:30", -(3 * 3600 + 1800)}};
  for (const auto& [zone, ahead_s] : zones) {
    ::setenv("TZ", zone, 1);
    ::tzset();
    const std::time_t from = std::time(nullptr);
    const TimeCode now = TimeCode::timeOfDay(25.0);
    const std::time_t to = std::time(nullptr);
    const auto secondOfDay = [ahead = ahead_s](std::time_t t) { return ((t + ahead) % 86400 + 86400) % 86400; };
    if (secondOfDay(to) < secondOfDay(from)) continue;  // midnight came in between
    EXPECT_EQ(now.rate, 25.0);
    EXPECT_GE(now.frame, secondOfDay(from) * 25) << zone;
    EXPECT_LT(now.frame, (secondOfDay(to) + 1) * 25) << zone;
  }
  if (saved != nullptr) ::setenv("TZ", before.c_str(), 1);
  else ::unsetenv("TZ");
  ::tzset();
  EXPECT_EQ(TimeCode::parseOption("10:00:00:00", 30).frame, 10 * 3600 * 30);
  EXPECT_THROW((void)TimeCode::parseOption("later", 30), Error);
}

TEST(SourcePos, FormatsWhatIsKnown) {
  EXPECT_EQ((SourcePos{"a.wrl", 3, 7}).str(), "a.wrl:3:7");
  EXPECT_EQ((SourcePos{"a.wrl", 3, 0}).str(), "a.wrl:3");
  EXPECT_EQ((SourcePos{"a.wrl", 0, 0}).str(), "a.wrl");
  EXPECT_STREQ(Error::at({"f.bvh", 2, 5}, "expected a number").what(), "f.bvh:2:5: expected a number");
}

TEST(RigidTransform, InverseAndComposition) {
  const RigidTransform a{Quat(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())), Vec3(1, -2, 0.5)};
  const RigidTransform b{Quat(Eigen::AngleAxisd(-1.1, Vec3(0, 1, 0))), Vec3(0.3, 0, 2)};
  const Vec3 p(0.2, -0.4, 1.5);
  EXPECT_LT((a.inverse().apply(a.apply(p)) - p).norm(), 1e-12);
  EXPECT_LT(((a * b).apply(p) - a.apply(b.apply(p))).norm(), 1e-12);
}

TEST(Isolate, ReturnsTheChildsBytes) {
  const std::string bytes = runIsolated("x", "test reader", [] { return std::string("hello\0world", 11); });
  EXPECT_EQ(bytes, std::string("hello\0world", 11));
}

TEST(Isolate, CarriesErrorsBack) {
  try {
    (void)runIsolated("x", "test reader", []() -> std::string { throw Error("f.wrl:3:4: expected '}'"); });
    FAIL();
  } catch (const Error& e) {
    EXPECT_STREQ(e.what(), "f.wrl:3:4: expected '}'");
    EXPECT_EQ(e.code(), ExitCode::BadInput);
  }
}

TEST(Isolate, SurvivesACrashingChild) {
  try {
    (void)runIsolated("bad.wrl", "VRML97 reader", []() -> std::string {
      std::raise(SIGSEGV);
      return {};
    });
    FAIL();
  } catch (const Error& e) {
    // "(signal 11)"; under AddressSanitizer its handler turns the crash into an exit status.
    EXPECT_NE(std::string(e.what()).find("bad.wrl: the VRML97 reader failed ("), std::string::npos) << e.what();
  }
}

TEST(Isolate, StopsAHangingChild) {
  IsolationLimits limits;
  limits.seconds = 0.5;
  try {
    (void)runIsolated("hang.3ds", "VRML97 reader", []() -> std::string {
      for (;;) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }, limits);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("time limit"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace drape
