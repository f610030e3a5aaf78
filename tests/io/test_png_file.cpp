// Serial tests for src/io/png_file and src/io/colormap.hpp.
#include "core/user_error.hpp"
#include "io/colormap.hpp"
#include "io/png_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
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

TEST(Colormap, NamedMapsAndEndpoints) {
  EXPECT_EQ(colormap_names(), (std::vector<std::string>{"grey", "viridis", "magma", "coolwarm"}));
  EXPECT_EQ(colormap_from_name("magma"), Colormap::magma);
  EXPECT_FALSE(colormap_from_name("jet").has_value());
  unsigned char c[3];
  colormap_rgb(Colormap::magma, 0.0, c);
  EXPECT_EQ((std::array<int, 3>{c[0], c[1], c[2]}), (std::array<int, 3>{0, 0, 4}));
  colormap_rgb(Colormap::magma, 1.0, c);
  EXPECT_EQ((std::array<int, 3>{c[0], c[1], c[2]}), (std::array<int, 3>{252, 253, 191}));
  colormap_rgb(Colormap::coolwarm, 0.0, c); // diverging: blue, light grey, red
  EXPECT_GT(c[2], c[0]);
  colormap_rgb(Colormap::coolwarm, 1.0, c);
  EXPECT_GT(c[0], c[2]);
  colormap_rgb(Colormap::coolwarm, 0.5, c);
  EXPECT_NEAR(c[0], c[2], 2);
  colormap_rgb(Colormap::grey, 0.5, c);
  EXPECT_EQ((std::array<int, 3>{c[0], c[1], c[2]}), (std::array<int, 3>{128, 128, 128}));
  colormap_rgb(Colormap::grey, std::nan(""), c);
  EXPECT_EQ((std::array<int, 3>{c[0], c[1], c[2]}), (std::array<int, 3>{255, 0, 255}));
}

TEST_F(PngFileTest, ScaleRepeatsEachCell) {
  const std::vector<double> f{0.0, 1.0, 2.0, 3.0, 4.0, 5.0}; // 3 x 2, j = 0 the bottom row
  FieldImageStyle st;
  st.colormap = Colormap::grey;
  st.scale = 3;
  write_field_png(file("s.png"), 3, 2, f.data(), 0.0, 5.0, st);
  const GreyImage img = read_png_grey(file("s.png"));
  ASSERT_EQ(img.width, 9);
  ASSERT_EQ(img.height, 6);
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 9; ++i)
      EXPECT_NEAR(img.value[i + 9 * j], std::lround(f[i / 3 + 3 * (j / 3)] / 5.0 * 255) / 255.0,
                  1e-12)
          << i << "," << j;
}

TEST_F(PngFileTest, Grey16KeepsSixteenBits) {
  std::vector<double> f(40);
  for (size_t k = 0; k < f.size(); ++k)
    f[k] = 0.001 * static_cast<double>(k * k);
  FieldImageStyle st;
  st.bits = 16;
  const double lo = 0.0, hi = f.back();
  write_field_png(file("g.png"), 8, 5, f.data(), lo, hi, st);
  const GreyImage img = read_png_grey(file("g.png"));
  ASSERT_EQ(img.width, 8);
  for (size_t k = 0; k < f.size(); ++k)
    EXPECT_NEAR(img.value[k], (f[k] - lo) / (hi - lo), 0.5 / 65535 + 1e-12) << k;
  std::ifstream in(file("g.png"), std::ios::binary);
  char head[26];
  in.read(head, 26);
  EXPECT_EQ(head[24], 16); // bit depth
  EXPECT_EQ(head[25], 0);  // grey
}

TEST_F(PngFileTest, ColorbarBesideTheField) {
  std::vector<double> f(16 * 64);
  for (size_t k = 0; k < f.size(); ++k)
    f[k] = static_cast<double>(k % 16);
  FieldImageStyle st;
  st.colorbar = true;
  st.scale = 2;
  write_field_png(file("c.png"), 16, 64, f.data(), 0.0, 15.0, st);
  const GreyImage img = read_png_grey(file("c.png"));
  EXPECT_EQ(img.height, 128);
  ASSERT_GT(img.width, 32 + 20);
  // the bar (a few pixels right of the field) runs from viridis(0) at the bottom to viridis(1)
  unsigned char lo[3], hi[3];
  viridis(0.0, lo);
  viridis(1.0, hi);
  const int x = 32 + 4 + 2; // field, gap (4 font pixels of 1), inside the bar
  EXPECT_NEAR(img.value[x], luminance(lo), 1e-9);
  EXPECT_NEAR(img.value[x + img.width * 127], luminance(hi), 1e-9);
  EXPECT_EQ(colorbar_labels(0.0, 15.0), (std::vector<std::string>{"0", "7.5", "15"}));
  // the labels are drawn in black right of the bar
  double darkest = 1.0;
  for (int j = 0; j < img.height; ++j)
    for (int i = x + 10; i < img.width; ++i)
      darkest = std::min(darkest, img.value[i + img.width * j]);
  EXPECT_EQ(darkest, 0.0);
}

TEST_F(PngFileTest, BadStyleIsAUserError) {
  const std::vector<double> f(4, 1.0);
  FieldImageStyle st;
  st.scale = 0;
  expect_user_error_naming([&] { write_field_png(file("b.png"), 2, 2, f.data(), 0, 1, st); },
                           "scale 0");
  EXPECT_FALSE(fs::exists(file("b.png")));
}
