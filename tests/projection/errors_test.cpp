#include "facet/projection/errors.hpp"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cstdint>
#include <limits>
#include <new>
#include <stdexcept>

#include "facet/projection/memory_budget.hpp"

namespace facet {
namespace {

void fail_inside(const char* outer, const char* inner) {
  const Activity a(outer);
  const Activity b(inner);
  throw std::bad_alloc();
}

TEST(Activity, NamesTheInnermostStepAnExceptionLeft) {
  EXPECT_THROW(fail_inside("reading the display d.json", "reading the warp p0.warp.exr"),
               std::bad_alloc);
  EXPECT_EQ(Activity::failed(), "reading the warp p0.warp.exr");
}

TEST(Activity, ForgetsTheFailureWhenTheNextStepStarts) {
  EXPECT_THROW(fail_inside("a", "b"), std::bad_alloc);
  {
    const Activity next("writing the lookup out.exr");
    EXPECT_EQ(Activity::failed(), "");
  }
  EXPECT_EQ(Activity::failed(), "");  // it ended without an exception
}

TEST(Activity, AStepThatHandlesItsOwnExceptionIsNotAFailure) {
  const Activity outer("importing");
  try {
    fail_inside("x", "y");
  } catch (const std::bad_alloc&) {
  }
  const Activity next("next step");
  EXPECT_EQ(Activity::failed(), "");
}

TEST(MemoryBudget, RefusesWhatTheAddressSpaceLimitCannotHold) {
  EXPECT_NO_THROW(require_memory(1024, "x.warp.exr", "output_size", "a small table"));
  EXPECT_THROW(require_memory(std::numeric_limits<std::uint64_t>::max() / 2, "x.warp.exr",
                              "output_size", "an absurd table"),
               InputError);
  try {
    require_memory(std::numeric_limits<std::uint64_t>::max() / 2, "x.warp.exr", "output_size",
                   "a lookup of 8192x8192 pixels");
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "x.warp.exr");
    EXPECT_NE(std::string(e.what()).find("a lookup of 8192x8192 pixels needs about"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace facet
