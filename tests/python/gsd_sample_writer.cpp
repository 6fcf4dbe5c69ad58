// Writes sample hardbody GSD files for tests/python/test_gsd_roundtrip.py, plus a JSON file with
// every value the files must read back as (after the hoomd schema's frame-0/default rules).
//
// usage: gsd_sample_writer OUT_DIR
//   OUT_DIR/trajectory.gsd   4 frames: 0-1 written, file closed, 2-3 appended after reopening
//   OUT_DIR/checkpoint.gsd   one frame, written twice with write_frame_atomic (second one wins)
//   OUT_DIR/expected.json    {"trajectory": [frame...], "checkpoint": frame}
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/gsd_hoomd.hpp"

namespace {

using hb::gsd::HoomdFrame;
using hb::gsd::LogArray;

// Deterministic values that need every bit of a double (not representable as float).
double value(int seed, int i) { return std::sin(0.7 * seed + 1.3 * i) * 3.3 + 1e-9 * i; }

HoomdFrame make_frame(std::uint64_t step, std::uint32_t N, int seed, bool rotated) {
  HoomdFrame f;
  f.step = step;
  f.box = {10.5f, 11.25f, 12.0f, 0.0f, 0.0f, 0.0f};
  f.N = N;
  f.types = {"ellipsoid", "sphere"};
  f.type_shapes = {hb::gsd::ellipsoid_shape(2.0, 1.0, 0.5), hb::gsd::sphere_shape(1.0)};
  LogArray pos{N, 3, {}};
  for (std::uint32_t i = 0; i < N; ++i) {
    f.type_id.push_back(i % 2);
    for (int k = 0; k < 3; ++k) {
      const double x = value(seed, static_cast<int>(3 * i + k));
      pos.values.push_back(x);
      f.position.push_back(static_cast<float>(x));
      f.velocity.push_back(static_cast<float>(value(seed + 1, static_cast<int>(3 * i + k))));
      f.image.push_back(static_cast<std::int32_t>(i) - k);
    }
    const double a = rotated ? 0.3 * (i + 1) + seed : 0.0;
    f.orientation.insert(f.orientation.end(), {static_cast<float>(std::cos(a)),
                                               static_cast<float>(std::sin(a) * 0.6), 0.0f,
                                               static_cast<float>(std::sin(a) * 0.8)});
    f.angmom.insert(f.angmom.end(), {0.0f, 0.5f * i, -0.25f * i, 1.0f});
  }
  f.log["hardbody/position_double"] = pos;
  f.log["hardbody/time"] = LogArray{1, 1, {value(seed, 100)}};
  f.log["hardbody/collisions"] = LogArray{1, 1, {static_cast<double>(1000 * step + 7)}};
  return f;
}

nlohmann::json to_json(const HoomdFrame& f) {
  nlohmann::json j;
  j["step"] = f.step;
  j["dimensions"] = f.dimensions;
  j["box"] = f.box;
  j["N"] = f.N;
  j["position"] = f.position;
  j["orientation"] = f.orientation;
  j["typeid"] = f.type_id;
  j["types"] = f.types;
  j["type_shapes"] = f.type_shapes;
  j["velocity"] = f.velocity;
  j["angmom"] = f.angmom;
  j["image"] = f.image;
  for (const auto& [key, a] : f.log)
    j["log"][key] = {{"shape", {a.rows, a.cols}}, {"values", a.values}};
  return j;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  try {
    std::filesystem::create_directories(dir);
    std::vector<HoomdFrame> frames = {
        make_frame(0, 5, 1, true),
        make_frame(100, 5, 2, true),
        make_frame(200, 3, 3, false),  // N changes: identity orientations fall back to the default
        make_frame(300, 3, 4, true),
    };
    frames[1].type_id = frames[0].type_id;    // unchanged: left out of frame 1
    frames[1].velocity = frames[0].velocity;  // unchanged: left out of frame 1
    {
      auto w = hb::gsd::HoomdWriter::create(dir / "trajectory.gsd");
      w.write_frame(frames[0]);
      w.write_frame(frames[1]);
      w.close();
    }
    {
      auto w = hb::gsd::HoomdWriter::append(dir / "trajectory.gsd");
      w.write_frame(frames[2]);
      w.write_frame(frames[3]);
      w.close();
    }
    hb::gsd::write_frame_atomic(dir / "checkpoint.gsd", make_frame(50, 4, 5, true));
    const HoomdFrame checkpoint = make_frame(60, 6, 6, true);
    hb::gsd::write_frame_atomic(dir / "checkpoint.gsd", checkpoint);

    nlohmann::json expected;
    for (const auto& f : frames) expected["trajectory"].push_back(to_json(f));
    expected["checkpoint"] = to_json(checkpoint);
    std::ofstream(dir / "expected.json") << expected.dump(1) << '\n';
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gsd_sample_writer: %s\n", e.what());
    return 1;
  }
  return 0;
}
