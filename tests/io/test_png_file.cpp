// Serial tests for src/io/png_file and src/io/colormap.hpp.
#include "core/user_error.hpp"
#include "io/colormap.hpp"
#include "io/png_file.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <unistd.h>

namespace fs = std::filesystem;
using morphogen::UserError;
using namespace morphogen::io;

namespace {

// A fresh scratch directory per test, removed afterwards.
class PngFileTest : public ::testing::Test {
protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() /
           ("morphogen_png_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::string file(const std::string& name) const { return (dir_ / name).string(); }

  fs::path dir_;
};

double luminance(const unsigned char* rgb) {
  return (0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]) / 255.0;
}

// Expect f() to throw UserError whose message contains `needle`.
template <class F> void expect_user_error_naming(F f, const std::string& needle) {
  try {
    f();
    ADD_FAILURE() << "expected UserError mentioning " << needle;
  } catch (const UserError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(needle), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "message should be one line: " << msg;
  }
}

} // namespace

TEST(Colormap, ViridisEndpointsMatchMatplotlib) {
  unsigned char rgb[3];
  viridis(0.0, rgb);
  EXPECT_EQ(rgb[0], 68);
  EXPECT_EQ(rgb[1], 1);
  EXPECT_EQ(rgb[2], 84);
  viridis(1.0, rgb);
  EXPECT_EQ(rgb[0], 253);
  EXPECT_EQ(rgb[1], 231);
  EXPECT_EQ(rgb[2], 37);
  // Clamping outside [0, 1].
  unsigned char lo[3], hi[3];
  viridis(-3.0, lo);
  viridis(7.0, hi);
  EXPECT_EQ(lo[0], 68);
  EXPECT_EQ(lo[2], 84);
  EXPECT_EQ(hi[0], 253);
  EXPECT_EQ(hi[2], 37);
  // NaN is magenta.
  viridis(std::nan(""), rgb);
  EXPECT_EQ(rgb[0], 255);
  EXPECT_EQ(rgb[1], 0);
  EXPECT_EQ(rgb[2], 255);
}

TEST(Colormap, ViridisLuminanceIsMonotone) {
  // matplotlib's float table has strictly increasing luminance. Rounding to 8 bits breaks that
  // between a few neighbouring entries (largest drop ~0.0008, at entry 95), but entries two or
  // more apart are still strictly ordered.
  for (std::size_t k = 1; k < kViridis.size(); ++k) {
    const double dl = luminance(kViridis[k].data()) - luminance(kViridis[k - 1].data());
    EXPECT_GT(dl, -0.5 / 255.0) << "entry " << k;
    if (k >= 2) {
      EXPECT_GT(luminance(kViridis[k].data()), luminance(kViridis[k - 2].data())) << "entry " << k;
    }
  }
}

TEST_F(PngFileTest, FieldRoundTripFlipsAndKeepsGradient) {
  // Field increases with j (upwards) and, more weakly, with i.
  const int nx = 7, ny = 9;
  std::vector<double> field(nx * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      field[i + nx * j] = 10.0 * j + 1.0 * i;
  const double lo = 0.0, hi = 10.0 * (ny - 1) + (nx - 1);
  const std::string path = file("field.png");
  write_field_png(path, nx, ny, field.data(), lo, hi);
  EXPECT_FALSE(fs::exists(path + ".tmp"));

  const GreyImage img = read_png_grey(path);
  ASSERT_EQ(img.width, nx);
  ASSERT_EQ(img.height, ny);
  ASSERT_EQ(img.value.size(), std::size_t(nx * ny));
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      // Exact expected value: the viridis entry for this sample, as stored in 8 bits.
      unsigned char rgb[3];
      viridis((field[i + nx * j] - lo) / (hi - lo), rgb);
      EXPECT_NEAR(img.value[i + nx * j], luminance(rgb), 1e-12) << i << "," << j;
      // Luminance is monotone along the gradient (viridis luminance increases with t).
      // Neighbouring samples are >= 3 table entries apart, where the 8-bit table is ordered.
      if (j > 0) {
        EXPECT_GT(img.value[i + nx * j], img.value[i + nx * (j - 1)]);
      }
      if (i > 0) {
        EXPECT_GT(img.value[i + nx * j], img.value[i - 1 + nx * j]);
      }
    }
  // Bottom row of the field (smallest values) is at j = 0 after reading back: dark viridis end.
  EXPECT_LT(img.value[0], 0.1);
  EXPECT_GT(img.value[nx - 1 + nx * (ny - 1)], 0.8);
}

TEST_F(PngFileTest, FieldDegenerateRangeMapsToMiddle) {
  const std::vector<double> field{1.0, 2.0, 3.0, 4.0};
  const std::string path = file("flat.png");
  write_field_png(path, 2, 2, field.data(), 5.0, 5.0);
  const GreyImage img = read_png_grey(path);
  unsigned char mid[3];
  viridis(0.5, mid);
  for (double v : img.value)
    EXPECT_NEAR(v, luminance(mid), 1e-12);
}

TEST_F(PngFileTest, RgbRoundTripLuminance) {
  const int w = 5, h = 3;
  std::vector<unsigned char> rgb(w * h * 3);
  for (int r = 0; r < h; ++r)
    for (int i = 0; i < w; ++i)
      for (int c = 0; c < 3; ++c)
        rgb[3 * (i + w * r) + c] = static_cast<unsigned char>((37 * r + 53 * i + 91 * c) % 256);
  const std::string path = file("rgb.png");
  write_png_rgb(path, w, h, rgb.data());
  const GreyImage img = read_png_grey(path);
  ASSERT_EQ(img.width, w);
  ASSERT_EQ(img.height, h);
  for (int r = 0; r < h; ++r)
    for (int i = 0; i < w; ++i) {
      const int j = h - 1 - r; // buffer row 0 is the top row; GreyImage j = 0 is the bottom
      EXPECT_NEAR(img.value[i + w * j], luminance(&rgb[3 * (i + w * r)]), 1e-12) << i << "," << r;
    }
}

TEST_F(PngFileTest, OverwriteReplacesExistingFile) {
  const std::string path = file("over.png");
  const unsigned char black[3] = {0, 0, 0}, white[3] = {255, 255, 255};
  write_png_rgb(path, 1, 1, black);
  write_png_rgb(path, 1, 1, white);
  EXPECT_DOUBLE_EQ(read_png_grey(path).value.at(0), 1.0);
}

TEST_F(PngFileTest, ReadMissingFileThrowsNamingPath) {
  const std::string path = file("does_not_exist.png");
  expect_user_error_naming([&] { read_png_grey(path); }, path);
}

TEST_F(PngFileTest, ReadNonPngThrows) {
  const std::string path = file("not_a_png.png");
  std::ofstream(path) << "this is plain text, not a PNG image\n";
  expect_user_error_naming([&] { read_png_grey(path); }, path);
  const std::string empty = file("empty.png");
  std::ofstream{empty};
  expect_user_error_naming([&] { read_png_grey(empty); }, empty);
}

TEST_F(PngFileTest, ReadTruncatedPngThrows) {
  const std::string path = file("trunc.png");
  std::vector<unsigned char> rgb(16 * 16 * 3, 100);
  write_png_rgb(path, 16, 16, rgb.data());
  fs::resize_file(path, fs::file_size(path) / 2);
  expect_user_error_naming([&] { read_png_grey(path); }, path);
}

TEST_F(PngFileTest, WriteIntoMissingDirectoryThrowsAndLeavesNoTmp) {
  const std::string path = file("no_such_dir/out.png");
  const unsigned char rgb[3] = {1, 2, 3};
  expect_user_error_naming([&] { write_png_rgb(path, 1, 1, rgb); }, path);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  const double f = 0.0;
  expect_user_error_naming([&] { write_field_png(path, 1, 1, &f, 0.0, 1.0); }, path);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST_F(PngFileTest, FailedRenameRemovesTmp) {
  // The target is an existing non-empty directory, so the final rename fails.
  const std::string path = file("target_dir");
  fs::create_directories(fs::path(path) / "child");
  const unsigned char rgb[3] = {1, 2, 3};
  expect_user_error_naming([&] { write_png_rgb(path, 1, 1, rgb); }, path);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
  EXPECT_TRUE(fs::is_directory(path));
}

TEST(SampleBilinear, ExactOnTwoByTwo) {
  GreyImage img;
  img.width = 2;
  img.height = 2;
  img.value = {0.0, 1.0,   // j = 0 (bottom): left, right
               0.25, 0.5}; // j = 1 (top)
  EXPECT_DOUBLE_EQ(sample_bilinear(img, 0.0, 0.0), 0.0);
  EXPECT_DOUBLE_EQ(sample_bilinear(img, 1.0, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(sample_bilinear(img, 0.0, 1.0), 0.25);
  EXPECT_DOUBLE_EQ(sample_bilinear(img, 1.0, 1.0), 0.5);
  EXPECT_DOUBLE_EQ(sample_bilinear(img, 0.5, 0.5), (0.0 + 1.0 + 0.25 + 0.5) / 4.0);
  EXPECT_DOUBLE_EQ(sample_bilinear(img, 0.5, 0.0), 0.5);
  EXPECT_DOUBLE_EQ(sample_bilinear(img, 0.0, 0.5), 0.125);
  // Clamped outside [0, 1].
  EXPECT_DOUBLE_EQ(sample_bilinear(img, -1.0, -2.0), 0.0);
  EXPECT_DOUBLE_EQ(sample_bilinear(img, 3.0, 1.5), 0.5);
}

TEST(SampleBilinear, SinglePixelAndEmpty) {
  GreyImage one;
  one.width = one.height = 1;
  one.value = {0.7};
  EXPECT_DOUBLE_EQ(sample_bilinear(one, 0.3, 0.9), 0.7);
  EXPECT_THROW(sample_bilinear(GreyImage{}, 0.5, 0.5), std::invalid_argument);
}
