#include "facet/interop/pfm.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>

#include "facet/projection/errors.hpp"

namespace facet::interop {
namespace {

TEST(Pfm, FormatThenParseKeepsEveryValueIncludingNaN) {
  PfmImage image;
  image.width = 3;
  image.height = 2;
  image.channels = 3;
  for (int k = 0; k < 18; ++k) image.values.push_back(0.25f * float(k) - 1.0f);
  image.values[5] = std::numeric_limits<float>::quiet_NaN();
  const PfmImage back = parse_pfm(format_pfm(image), "mem.pfm");
  ASSERT_EQ(back.width, 3);
  ASSERT_EQ(back.height, 2);
  ASSERT_EQ(back.channels, 3);
  for (int k = 0; k < 18; ++k) {
    if (k == 5) {
      EXPECT_TRUE(std::isnan(back.values[k]));
    } else {
      EXPECT_EQ(back.values[k], image.values[k]);
    }
  }
}

TEST(Pfm, ReadsBigEndianAndOneChannelFiles) {
  std::string bytes = "Pf\n2 1\n1.0\n";
  for (float value : {1.5f, -2.0f}) {
    std::uint32_t word;
    std::memcpy(&word, &value, 4);
    if constexpr (std::endian::native == std::endian::little) word = __builtin_bswap32(word);
    bytes.append(reinterpret_cast<const char*>(&word), 4);
  }
  const PfmImage image = parse_pfm(bytes, "be.pfm");
  EXPECT_EQ(image.channels, 1);
  EXPECT_EQ(image.at(0, 0, 0), 1.5f);
  EXPECT_EQ(image.at(1, 0, 0), -2.0f);
}

TEST(Pfm, BadFilesNameTheField) {
  const auto field_of = [](const std::string& bytes) {
    try {
      parse_pfm(bytes, "bad.pfm");
    } catch (const InputError& e) {
      EXPECT_EQ(e.source(), "bad.pfm");
      return e.field();
    }
    return std::string("no error");
  };
  EXPECT_EQ(field_of(""), "header");
  EXPECT_EQ(field_of("P6\n2 2\n255\n"), "header");
  EXPECT_EQ(field_of("PF\n-2 2\n-1\n"), "width");
  EXPECT_EQ(field_of("PF\n2 x\n-1\n"), "height");
  EXPECT_EQ(field_of("PF\n2 2\nabc\n"), "scale");
  EXPECT_EQ(field_of("PF\n2 2\n0\n"), "scale");
  EXPECT_EQ(field_of("PF\n99999 99999\n-1\n"), "width, height");
  EXPECT_EQ(field_of("PF\n2 2\n-1\n" + std::string(47, '\0')), "data");
  EXPECT_EQ(field_of("PF\n2 2\n-1"), "scale");
}

}  // namespace
}  // namespace facet::interop
