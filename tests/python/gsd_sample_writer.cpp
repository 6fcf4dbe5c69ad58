// Writes sample hardbody GSD files for tests/python/test_gsd_roundtrip.py, plus a JSON file with
// every value the files must read back as (after the hoomd schema's frame-0/default rules).
//
// usage: gsd_sample_writer OUT_DIR
//   OUT_DIR/trajectory.gsd   4 frames: 0-1 written, file closed, 2-3 appended after reopening
//   OUT_DIR/checkpoint.gsd   one frame, written twice with write_frame_atomic (second one wins)
//   OUT_DIR/big.gsd          300 frames, 101 names: index and namelist outgrow their first blocks
//                            (frame f: "value" = uint64 [f, 7], "grow/.../<f % 100>" = int32 [-f])
//   OUT_DIR/expected.json    {"trajectory": [frame...], "checkpoint": frame, "big": {...}}
//
// usage: gsd_sample_writer --dump FILE
//   prints every frame of FILE as read by hb::gsd::read_frame, as JSON (same keys as above), to
//   check hardbody's reader on files written by the reference implementation.
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>

#include "io/gsd_hoomd.hpp"
#include "io/gsd_sample_frame.hpp"

namespace {

using hb::gsd::HoomdFrame;
using hb::gsd::test::sample_frame;

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

int dump(const std::filesystem::path& file) {
  const hb::gsd::Reader r(file);
  nlohmann::json frames = nlohmann::json::array();
  for (std::uint64_t i = 0; i < r.nframes(); ++i) frames.push_back(to_json(read_frame(r, i)));
  std::printf("%s\n", frames.dump().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2 && !(argc == 3 && std::string(argv[1]) == "--dump")) {
    std::fprintf(stderr, "usage: %s OUT_DIR | --dump FILE\n", argv[0]);
    return 2;
  }
  try {
    if (argc == 3) return dump(argv[2]);
    const std::filesystem::path dir = argv[1];
    std::filesystem::create_directories(dir);
    std::vector<HoomdFrame> frames = {
        sample_frame(0, 5, 1),
        sample_frame(100, 5, 2),
        sample_frame(200, 3, 3),
        sample_frame(300, 3, 4),
    };
    hb::gsd::test::set_identity_orientations(frames[2]);  // N differs: left out as the default
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
    hb::gsd::write_frame_atomic(dir / "checkpoint.gsd", sample_frame(50, 4, 5));
    const HoomdFrame checkpoint = sample_frame(60, 6, 6);
    hb::gsd::write_frame_atomic(dir / "checkpoint.gsd", checkpoint);

    constexpr int kBigFrames = 300, kBigNames = 100;
    {
      auto w = hb::gsd::Writer::create(dir / "big.gsd", "hardbody", "test", {1, 0});
      for (int f = 0; f < kBigFrames; ++f) {
        w.write_chunk<std::uint64_t>("value", 1, 2, std::vector<std::uint64_t>{std::uint64_t(f), 7});
        w.write_chunk<std::int32_t>("grow/a/rather/long/chunk/name/" + std::to_string(f % kBigNames),
                                    1, 1, std::vector<std::int32_t>{-f});
        w.end_frame();
      }
    }

    nlohmann::json expected;
    expected["big"] = {{"frames", kBigFrames}, {"names", kBigNames},
                       {"prefix", "grow/a/rather/long/chunk/name/"}};
    for (const auto& f : frames) expected["trajectory"].push_back(to_json(f));
    expected["checkpoint"] = to_json(checkpoint);
    std::ofstream(dir / "expected.json") << expected.dump(1) << '\n';
  } catch (const std::exception& e) {
    std::fprintf(stderr, "gsd_sample_writer: %s\n", e.what());
    return 1;
  }
  return 0;
}
