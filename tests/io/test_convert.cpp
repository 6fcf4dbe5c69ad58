// GSD -> extended XYZ: every value read back from the text (double data bit for bit, float data
// as the exact float), OVITO's quaternion order, shapes, box and origin, frame ranges, and errors
// that leave no output behind.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "io/convert.hpp"
#include "io/gsd_hoomd.hpp"
#include "io/gsd_test_util.hpp"

namespace hb {
namespace {

using gsd::HoomdFrame;
using gsd::LogArray;
using gsd::test::expect_error;
using gsd::test::TempDir;

// ---- a small extended-XYZ reader for the tests ----

struct XyzFrame {
  std::size_t N = 0;
  std::map<std::string, std::string> info;  // comment-line key -> value (quotes removed)
  std::vector<std::vector<std::string>> rows;
};

std::map<std::string, std::string> parse_comment(const std::string& line) {
  std::map<std::string, std::string> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && line[i] == ' ') ++i;
    if (i >= line.size()) break;
    const std::size_t eq = line.find('=', i);
    if (eq == std::string::npos) {
      ADD_FAILURE() << "no '=' in comment line at " << i << ": " << line;
      break;
    }
    const std::string key = line.substr(i, eq - i);
    std::string value;
    i = eq + 1;
    if (i < line.size() && line[i] == '"') {
      const std::size_t close = line.find('"', i + 1);
      if (close == std::string::npos) {
        ADD_FAILURE() << "unterminated quote in: " << line;
        break;
      }
      value = line.substr(i + 1, close - i - 1);
      i = close + 1;
    } else {
      const std::size_t sp = std::min(line.find(' ', i), line.size());
      value = line.substr(i, sp - i);
      i = sp;
    }
    EXPECT_FALSE(out.count(key)) << "repeated key " << key;
    out[key] = value;
  }
  return out;
}

std::vector<std::string> split(const std::string& s) {
  std::istringstream in(s);
  std::vector<std::string> out;
  for (std::string w; in >> w;) out.push_back(w);
  return out;
}

std::vector<XyzFrame> read_xyz(const std::filesystem::path& p) {
  std::ifstream in(p);
  EXPECT_TRUE(in) << "cannot open " << p;
  std::vector<XyzFrame> frames;
  std::string line;
  while (std::getline(in, line)) {
    XyzFrame f;
    f.N = std::stoul(line);
    if (!std::getline(in, line)) {
      ADD_FAILURE() << "missing comment line";
      break;
    }
    f.info = parse_comment(line);
    for (std::size_t i = 0; i < f.N && std::getline(in, line); ++i) f.rows.push_back(split(line));
    EXPECT_EQ(f.rows.size(), f.N);
    frames.push_back(std::move(f));
  }
  return frames;
}

double num(const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  EXPECT_EQ(*end, '\0') << "not a number: " << s;
  return v;
}
std::vector<double> nums(const std::string& s) {
  std::vector<double> out;
  for (const auto& w : split(s)) out.push_back(num(w));
  return out;
}
bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

#define EXPECT_BITS(text, want) \
  EXPECT_TRUE(same_bits(num(text), (want))) << (text) << " vs " << (want)

// ---- sample trajectories ----

// Values that need every bit of a double.
double value(int frame, int i) { return std::sin(0.9 * frame + 1.7 * i) * 4.1 + 1e-10 * (i + 1); }

// Types: sphere (d = 1.5), ellipsoid (2, 1, 0.5). N = 5.
HoomdFrame sample(int k, bool with_doubles) {
  HoomdFrame f;
  f.step = 1000 + 250 * static_cast<std::uint64_t>(k);
  f.N = 5;
  f.box = {10.5f, 11.25f, 12.0f, 0.0f, 0.0f, 0.0f};
  f.types = {"sph", "ell"};
  f.type_shapes = {gsd::sphere_shape(1.5), gsd::ellipsoid_shape(2.0, 1.0, 0.5)};
  LogArray pos{f.N, 3, {}}, quat{f.N, 4, {}}, vel{f.N, 3, {}};
  for (std::uint32_t i = 0; i < f.N; ++i) {
    f.type_id.push_back(i % 2);
    for (int c = 0; c < 3; ++c) {
      pos.values.push_back(value(k, 3 * static_cast<int>(i) + c));
      vel.values.push_back(value(k + 7, 3 * static_cast<int>(i) + c));
    }
    // A unit quaternion [w, x, y, z] with four distinct components.
    const double a = 0.4 + 0.3 * i + k, w = std::cos(a), s = std::sin(a);
    const double axis[3] = {0.48, 0.6, 0.64};
    quat.values.insert(quat.values.end(), {w, s * axis[0], s * axis[1], s * axis[2]});
  }
  for (double v : pos.values) f.position.push_back(static_cast<float>(v));
  for (double v : quat.values) f.orientation.push_back(static_cast<float>(v));
  for (double v : vel.values) f.velocity.push_back(static_cast<float>(v));
  if (with_doubles) {
    f.log["particles/hardbody/position_double"] = pos;
    f.log["particles/hardbody/orientation_double"] = quat;
    f.log["particles/hardbody/velocity_double"] = vel;
    f.log["hardbody/time"] = LogArray{1, 1, {0.1 * 3 + k / 3.0}};
  }
  return f;
}

void write_gsd(const std::filesystem::path& p, const std::vector<HoomdFrame>& frames) {
  auto w = gsd::HoomdWriter::create(p);
  for (const auto& f : frames) w.write_frame(f);
  w.close();
}

constexpr const char* kProps =
    "species:S:1:pos:R:3:orientation:R:4:aspherical_shape:R:3:velo:R:3";

TEST(Convert, TwoFramesDoublePrecisionEveryValue) {
  TempDir dir;
  const auto in = dir / "traj.gsd";
  const auto out = dir / "traj.xyz";
  const std::vector<HoomdFrame> frames{sample(0, true), sample(1, true)};
  write_gsd(in, frames);
  convert_gsd_to_xyz(in.string(), out.string());
  EXPECT_FALSE(std::filesystem::exists(out.string() + ".tmp"));

  const auto xyz = read_xyz(out);
  ASSERT_EQ(xyz.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const HoomdFrame& f = frames[k];
    const XyzFrame& x = xyz[k];
    ASSERT_EQ(x.N, f.N);
    EXPECT_EQ(x.info.at("Properties"), kProps);
    EXPECT_EQ(x.info.at("pbc"), "T T T");
    EXPECT_EQ(x.info.at("Step"), std::to_string(f.step));
    EXPECT_BITS(x.info.at("Time"), f.log.at("hardbody/time").values[0]);
    EXPECT_EQ(nums(x.info.at("Lattice")),
              (std::vector<double>{10.5, 0, 0, 0, 11.25, 0, 0, 0, 12.0}));
    EXPECT_EQ(nums(x.info.at("Origin")), (std::vector<double>{-5.25, -5.625, -6.0}));

    const auto& pos = f.log.at("particles/hardbody/position_double").values;
    const auto& quat = f.log.at("particles/hardbody/orientation_double").values;
    const auto& vel = f.log.at("particles/hardbody/velocity_double").values;
    for (std::size_t i = 0; i < f.N; ++i) {
      const auto& r = x.rows[i];
      ASSERT_EQ(r.size(), 14u);
      const bool sphere = i % 2 == 0;
      EXPECT_EQ(r[0], sphere ? "sph" : "ell");
      for (int c = 0; c < 3; ++c) EXPECT_BITS(r[1 + c], pos[3 * i + c]);
      // OVITO order x y z w from GSD's w x y z.
      EXPECT_BITS(r[4], quat[4 * i + 1]);
      EXPECT_BITS(r[5], quat[4 * i + 2]);
      EXPECT_BITS(r[6], quat[4 * i + 3]);
      EXPECT_BITS(r[7], quat[4 * i + 0]);
      const std::vector<double> shape{num(r[8]), num(r[9]), num(r[10])};
      EXPECT_EQ(shape, sphere ? (std::vector<double>{0.75, 0.75, 0.75})
                              : (std::vector<double>{2.0, 1.0, 0.5}));
      for (int c = 0; c < 3; ++c) EXPECT_BITS(r[11 + c], vel[3 * i + c]);
    }
  }
}

TEST(Convert, FloatChunksWhenNoDoubleLogs) {
  TempDir dir;
  const auto in = dir / "float.gsd";
  const auto out = dir / "float.xyz";
  const std::vector<HoomdFrame> frames{sample(2, false), sample(3, false)};
  write_gsd(in, frames);
  convert_gsd_to_xyz(in.string(), out.string());
  const auto xyz = read_xyz(out);
  ASSERT_EQ(xyz.size(), 2u);
  for (int k = 0; k < 2; ++k) {
    const HoomdFrame& f = frames[k];
    const XyzFrame& x = xyz[k];
    EXPECT_FALSE(x.info.count("Time"));
    EXPECT_EQ(x.info.at("Step"), std::to_string(f.step));
    for (std::size_t i = 0; i < f.N; ++i) {
      const auto& r = x.rows[i];
      ASSERT_EQ(r.size(), 14u);
      // Every float is written so that it reads back as the same float.
      for (int c = 0; c < 3; ++c) EXPECT_EQ(static_cast<float>(num(r[1 + c])), f.position[3 * i + c]);
      EXPECT_EQ(static_cast<float>(num(r[4])), f.orientation[4 * i + 1]);
      EXPECT_EQ(static_cast<float>(num(r[5])), f.orientation[4 * i + 2]);
      EXPECT_EQ(static_cast<float>(num(r[6])), f.orientation[4 * i + 3]);
      EXPECT_EQ(static_cast<float>(num(r[7])), f.orientation[4 * i + 0]);
      for (int c = 0; c < 3; ++c)
        EXPECT_EQ(static_cast<float>(num(r[11 + c])), f.velocity[3 * i + c]);
      // Short text, not 17 digits of float noise.
      EXPECT_LE(r[1].size(), 16u) << r[1];
    }
  }
}

TEST(Convert, TriclinicLatticeOriginFromFileAndOption) {
  TempDir dir;
  const auto in = dir / "tri.gsd";
  HoomdFrame f = sample(0, true);
  f.box = {4.0f, 5.0f, 8.0f, 0.5f, -0.25f, 0.125f};
  write_gsd(in, {f});
  const auto out = dir / "tri.xyz";
  convert_gsd_to_xyz(in.string(), out.string());
  auto x = read_xyz(out).at(0);
  EXPECT_EQ(nums(x.info.at("Lattice")),
            (std::vector<double>{4, 0, 0, 2.5, 5, 0, -2, 1, 8}));
  EXPECT_EQ(nums(x.info.at("Origin")), (std::vector<double>{-2.25, -3.0, -4.0}));

  // A file that says where its box starts (hardbody positions in [0, L)).
  f.log["hardbody/box_origin"] = LogArray{1, 3, {0.0, 0.0, 0.0}};
  f.log["hardbody/box_double"] = LogArray{1, 6, {4.1, 5.2, 8.3, 0.0, 0.0, 0.0}};
  write_gsd(in, {f});
  convert_gsd_to_xyz(in.string(), out.string());
  x = read_xyz(out).at(0);
  EXPECT_EQ(nums(x.info.at("Origin")), (std::vector<double>{0, 0, 0}));
  EXPECT_EQ(nums(x.info.at("Lattice")),
            (std::vector<double>{4.1, 0, 0, 0, 5.2, 0, 0, 0, 8.3}));

  // The caller's origin wins.
  ConvertOptions opt;
  opt.origin = std::array<double, 3>{1.5, -2.0, 0.25};
  convert_gsd_to_xyz(in.string(), out.string(), opt);
  x = read_xyz(out).at(0);
  EXPECT_EQ(nums(x.info.at("Origin")), (std::vector<double>{1.5, -2.0, 0.25}));
}

TEST(Convert, FrameRangeAndStride) {
  TempDir dir;
  const auto in = dir / "five.gsd";
  std::vector<HoomdFrame> frames;
  for (int k = 0; k < 5; ++k) frames.push_back(sample(k, true));
  write_gsd(in, frames);
  const auto out = dir / "part.xyz";
  auto steps = [&] {
    std::vector<std::string> s;
    for (const auto& x : read_xyz(out)) s.push_back(x.info.at("Step"));
    return s;
  };
  ConvertOptions opt;
  opt.first = 1;
  opt.stride = 2;
  convert_gsd_to_xyz(in.string(), out.string(), opt);
  EXPECT_EQ(steps(), (std::vector<std::string>{"1250", "1750"}));
  opt.end = 3;
  convert_gsd_to_xyz(in.string(), out.string(), opt);
  EXPECT_EQ(steps(), (std::vector<std::string>{"1250"}));
  opt.first = 4;
  opt.end = std::nullopt;
  opt.stride = std::numeric_limits<std::uint64_t>::max();
  convert_gsd_to_xyz(in.string(), out.string(), opt);
  EXPECT_EQ(steps(), (std::vector<std::string>{"2000"}));

  opt = {};
  opt.end = 6;
  expect_error<std::runtime_error>([&] { convert_gsd_to_xyz(in.string(), out.string(), opt); },
                                   {in.string(), "frame range"});
  opt = {};
  opt.stride = 0;
  expect_error<std::runtime_error>([&] { convert_gsd_to_xyz(in.string(), out.string(), opt); },
                                   {in.string(), "stride"});
}

TEST(Convert, ShapeSemiAxes) {
  EXPECT_EQ(shape_semi_axes(gsd::sphere_shape(3.0)), (std::array<double, 3>{1.5, 1.5, 1.5}));
  EXPECT_EQ(shape_semi_axes(gsd::ellipsoid_shape(0.3, 0.2, 0.1)),
            (std::array<double, 3>{0.3, 0.2, 0.1}));
  EXPECT_EQ(shape_semi_axes(gsd::convex_polyhedron_shape({{1, 0, 0}, {0, 2, 0}, {0, 0, 3},
                                                           {-1.5, -1, -1}}, 0.25)),
            (std::array<double, 3>{1.75, 2.25, 3.25}));
  EXPECT_EQ(shape_semi_axes(R"({"type":"SphereUnion","centers":[[1,0,0],[-1,0,0]],)"
                            R"("diameters":[1,2]})"),
            (std::array<double, 3>{2.0, 1.0, 1.0}));
  expect_error<std::invalid_argument>([] { shape_semi_axes(R"({"type":"Polygon"})"); },
                                      {"Polygon"});
  expect_error<std::invalid_argument>(
      [] { shape_semi_axes(R"({"type":"Ellipsoid","a":1,"b":-1,"c":1})"); }, {"'b'"});
  expect_error<std::invalid_argument>([] { shape_semi_axes("{not json"); }, {"not JSON"});
}

TEST(Convert, UnknownShapeIsAnErrorUnlessAllowed) {
  TempDir dir;
  const auto in = dir / "poly.gsd";
  const auto out = dir / "poly.xyz";
  HoomdFrame f = sample(0, false);
  f.type_shapes[1] = R"({"type":"Mesh","vertices":[[0,0,0]],"indices":[[0]]})";
  write_gsd(in, {f});
  expect_error<std::runtime_error>([&] { convert_gsd_to_xyz(in.string(), out.string()); },
                                   {in.string(), "frame 0", "'ell'", "Mesh"});
  EXPECT_FALSE(std::filesystem::exists(out));
  ConvertOptions opt;
  opt.allow_unknown_shapes = true;
  convert_gsd_to_xyz(in.string(), out.string(), opt);
  const auto x = read_xyz(out).at(0);
  EXPECT_EQ(x.rows[1][8], "0");
  EXPECT_EQ(x.rows[1][0], "ell");
  EXPECT_EQ(x.rows[0][8], "0.75");

  // No type_shapes at all.
  f.type_shapes.clear();
  write_gsd(in, {f});
  expect_error<std::runtime_error>([&] { convert_gsd_to_xyz(in.string(), out.string()); },
                                   {in.string(), "no type_shapes"});
}

TEST(Convert, TypeNameWithBlankIsAnError) {
  TempDir dir;
  const auto in = dir / "blank.gsd";
  HoomdFrame f = sample(0, true);
  f.types[0] = "big sphere";
  write_gsd(in, {f});
  expect_error<std::runtime_error>(
      [&] { convert_gsd_to_xyz(in.string(), (dir / "blank.xyz").string()); },
      {in.string(), "'big sphere'"});
  EXPECT_FALSE(std::filesystem::exists(dir / "blank.xyz"));
}

TEST(Convert, CorruptOrMissingInputLeavesNoOutput) {
  TempDir dir;
  const auto in = dir / "bad.gsd";
  const auto out = dir / "bad.xyz";
  const std::string tmp = out.string() + ".tmp";

  expect_error<std::runtime_error>(
      [&] { convert_gsd_to_xyz((dir / "missing.gsd").string(), out.string()); },
      {(dir / "missing.gsd").string()});
  EXPECT_FALSE(std::filesystem::exists(out));

  write_gsd(in, {sample(0, true), sample(1, true)});
  gsd::test::patch<std::uint64_t>(in, 0, 0x0123456789abcdefull);  // bad magic
  expect_error<std::runtime_error>([&] { convert_gsd_to_xyz(in.string(), out.string()); },
                                   {in.string()});
  EXPECT_FALSE(std::filesystem::exists(out));
  EXPECT_FALSE(std::filesystem::exists(tmp));

  // Truncated: an existing output stays as it was.
  write_gsd(in, {sample(0, true), sample(1, true)});
  { std::ofstream(out) << "previous\n"; }
  std::filesystem::resize_file(in, std::filesystem::file_size(in) / 2);
  expect_error<std::runtime_error>([&] { convert_gsd_to_xyz(in.string(), out.string()); },
                                   {in.string()});
  EXPECT_FALSE(std::filesystem::exists(tmp));
  std::ifstream prev(out);
  std::string line;
  std::getline(prev, line);
  EXPECT_EQ(line, "previous");

  // Not a GSD file at all.
  { std::ofstream(in) << "hello\n"; }
  expect_error<std::runtime_error>([&] { convert_gsd_to_xyz(in.string(), out.string()); },
                                   {in.string()});
}

TEST(Convert, RefusesToOverwriteTheInput) {
  TempDir dir;
  const auto in = dir / "same.gsd";
  write_gsd(in, {sample(0, true)});
  const auto before = gsd::test::file_bytes(in);
  expect_error<std::runtime_error>([&] { convert_gsd_to_xyz(in.string(), in.string()); },
                                   {"replace the input"});
  EXPECT_EQ(gsd::test::file_bytes(in), before);
}

TEST(Convert, WrongShapeOfDoubleLogChunkIsAnError) {
  TempDir dir;
  const auto in = dir / "shape.gsd";
  HoomdFrame f = sample(0, true);
  f.log["particles/hardbody/velocity_double"] = LogArray{f.N, 2, std::vector<double>(2 * f.N)};
  write_gsd(in, {f});
  expect_error<std::runtime_error>(
      [&] { convert_gsd_to_xyz(in.string(), (dir / "shape.xyz").string()); },
      {in.string(), "velocity_double", "5 x 2"});
}

}  // namespace
}  // namespace hb
