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

TEST(InputError, NamesAnOptionByItsLibraryNameUntilItIsShownAsAFlag) {
  const InputError plain("d.json", "render.tolerance_px", "a positive number");
  EXPECT_EQ(plain.option(), "");
  EXPECT_STREQ(plain.with_option_shown_as("--tolerance").what(),
               "d.json: field 'render.tolerance_px': a positive number");

  const InputError field("command line", OptionName{"fov_deg"}, "degrees in (0, 360]");
  EXPECT_EQ(field.option(), "fov_deg");
  EXPECT_STREQ(field.what(), "command line: field 'fov_deg': degrees in (0, 360]");
  const InputError shown = field.with_option_shown_as("--fov");
  EXPECT_STREQ(shown.what(), "command line: field '--fov': degrees in (0, 360]");
  EXPECT_EQ(shown.option(), "");  // a flag is no library name
  EXPECT_EQ(shown.source(), "command line");

  const InputError alone(OptionName{"average"}, "a number of exposures >= 1");
  EXPECT_EQ(alone.option(), "average");
  EXPECT_STREQ(alone.what(), "average: a number of exposures >= 1");
  EXPECT_STREQ(alone.with_option_shown_as("--average").what(),
               "--average: a number of exposures >= 1");

  // A helper's field argument carries the option through (InputField).
  const InputField out = OptionName{"out"};
  EXPECT_EQ(InputError("out/", out, "an empty folder").option(), "out");
  EXPECT_EQ(InputError("out/", "--out", "an empty folder").option(), "");
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
