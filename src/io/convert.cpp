// GSD trajectory -> extended XYZ; see convert.hpp and docs/convert.md.
#include "io/convert.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <iterator>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string_view>
#include <vector>

#include "io/gsd_hoomd.hpp"

namespace hb {

namespace {

constexpr std::string_view kProperties =
    "species:S:1:pos:R:3:orientation:R:4:aspherical_shape:R:3:velo:R:3";

// Log keys (without the "log/" prefix).
constexpr const char* kPositionDouble = "particles/hardbody/position_double";
constexpr const char* kOrientationDouble = "particles/hardbody/orientation_double";
constexpr const char* kVelocityDouble = "particles/hardbody/velocity_double";
constexpr const char* kTime = "hardbody/time";
constexpr const char* kBoxDouble = "hardbody/box_double";
constexpr const char* kBoxOrigin = "hardbody/box_origin";

using Json = nlohmann::json;

double positive_number(const Json& j, const char* key, std::string_view type) {
  if (!j.contains(key) || !j.at(key).is_number())
    throw std::invalid_argument(fmt::format("{} shape needs a number '{}'", type, key));
  const double v = j.at(key).get<double>();
  if (!(v > 0.0) || !std::isfinite(v))
    throw std::invalid_argument(fmt::format("{} shape has '{}' = {}, expected > 0", type, key, v));
  return v;
}

double rounding_radius(const Json& j, std::string_view type) {
  if (!j.contains("rounding_radius")) return 0.0;
  const Json& r = j.at("rounding_radius");
  if (!r.is_number() || !(r.get<double>() >= 0.0) || !std::isfinite(r.get<double>()))
    throw std::invalid_argument(fmt::format("{} shape has a bad 'rounding_radius'", type));
  return r.get<double>();
}

// Largest |coordinate| per axis over a list of points (JSON arrays of 3 numbers), each padded by
// pad[i] (0 if pad is empty).
std::array<double, 3> half_extents(const Json& points, const std::vector<double>& pad,
                                   std::string_view type, const char* key) {
  if (!points.is_array() || points.empty())
    throw std::invalid_argument(fmt::format("{} shape needs a non-empty array '{}'", type, key));
  std::array<double, 3> h{0.0, 0.0, 0.0};
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Json& p = points[i];
    if (!p.is_array() || p.size() != 3 || !p[0].is_number() || !p[1].is_number() ||
        !p[2].is_number())
      throw std::invalid_argument(
          fmt::format("{} shape: '{}' entry {} is not 3 numbers", type, key, i));
    const double r = pad.empty() ? 0.0 : pad[i];
    for (int k = 0; k < 3; ++k) h[k] = std::max(h[k], std::abs(p[k].get<double>()) + r);
  }
  for (double v : h)
    if (!std::isfinite(v))
      throw std::invalid_argument(fmt::format("{} shape has a non-finite '{}'", type, key));
  return h;
}

// Semi-axes of a known shape; nullopt for a shape type without a rule here.
std::optional<std::array<double, 3>> known_semi_axes(const std::string& text) {
  Json j;
  try {
    j = Json::parse(text);
  } catch (const Json::exception& e) {
    throw std::invalid_argument(fmt::format("type_shapes entry is not JSON: {}", e.what()));
  }
  if (!j.is_object() || !j.contains("type") || !j.at("type").is_string())
    throw std::invalid_argument("type_shapes entry has no string 'type'");
  const std::string type = j.at("type").get<std::string>();
  if (type == "Sphere") {
    const double r = 0.5 * positive_number(j, "diameter", type);
    return std::array<double, 3>{r, r, r};
  }
  if (type == "Ellipsoid")
    return std::array<double, 3>{positive_number(j, "a", type), positive_number(j, "b", type),
                                 positive_number(j, "c", type)};
  if (type == "ConvexPolyhedron" || type == "ConvexSpheropolyhedron") {
    const double r = rounding_radius(j, type);
    if (!j.contains("vertices"))
      throw std::invalid_argument(fmt::format("{} shape needs 'vertices'", type));
    auto h = half_extents(j.at("vertices"), {}, type, "vertices");
    for (double& v : h) v += r;
    return h;
  }
  if (type == "SphereUnion") {
    if (!j.contains("centers") || !j.contains("diameters") || !j.at("diameters").is_array() ||
        j.at("diameters").size() != j.at("centers").size())
      throw std::invalid_argument("SphereUnion shape needs 'centers' and as many 'diameters'");
    std::vector<double> radii;
    for (const Json& d : j.at("diameters")) {
      if (!d.is_number() || !(d.get<double>() > 0.0))
        throw std::invalid_argument("SphereUnion shape has a non-positive diameter");
      radii.push_back(0.5 * d.get<double>());
    }
    return half_extents(j.at("centers"), radii, type, "centers");
  }
  return std::nullopt;
}

// Text that reads back to exactly v (shortest round-trip form).
template <class T>
void put(std::string& out, T v) {
  fmt::format_to(std::back_inserter(out), " {}", v);
}

// A per-particle array: the double log chunk `key` if the frame has it (checked to be N x cols),
// else the float32 chunk.
struct Column {
  const double* d = nullptr;
  const float* f = nullptr;
  void put_row(std::string& out, std::size_t i, const std::array<int, 4>& order, int cols) const {
    for (int k = 0; k < cols; ++k) {
      const std::size_t at = i * static_cast<std::size_t>(cols) + static_cast<std::size_t>(order[k]);
      if (d) put(out, d[at]);
      else put(out, f[at]);
    }
  }
};

class Converter {
 public:
  Converter(std::string gsd_path, const ConvertOptions& opt) : path_(std::move(gsd_path)), opt_(opt) {}

  [[noreturn]] void fail(std::uint64_t frame, const std::string& what) const {
    throw std::runtime_error(fmt::format("{}: frame {}: {}", path_, frame, what));
  }

  const gsd::LogArray* log(const gsd::HoomdFrame& f, std::uint64_t i, const char* key,
                           std::uint64_t rows, std::uint32_t cols) const {
    const auto it = f.log.find(key);
    if (it == f.log.end()) return nullptr;
    const gsd::LogArray& a = it->second;
    if (a.rows != rows || a.cols != cols || a.values.size() != rows * cols)
      fail(i, fmt::format("log chunk 'log/{}' is {} x {}, expected {} x {}", key, a.rows, a.cols,
                          rows, cols));
    return &a;
  }

  Column column(const gsd::HoomdFrame& f, std::uint64_t i, const char* key,
                const std::vector<float>& fallback, std::uint32_t cols) const {
    if (const gsd::LogArray* a = log(f, i, key, f.N, cols)) return Column{a->values.data(), nullptr};
    if (fallback.size() != std::size_t{f.N} * cols)
      fail(i, fmt::format("a per-particle array has {} values, expected {}", fallback.size(),
                          std::size_t{f.N} * cols));
    return Column{nullptr, fallback.data()};
  }

  // Appends frame i to out.
  void format_frame(const gsd::HoomdFrame& f, std::uint64_t i, std::string& out) const {
    // Box: lattice vectors a1 = (Lx,0,0), a2 = (xy Ly, Ly, 0), a3 = (xz Lz, yz Lz, Lz).
    std::array<double, 6> box{};
    if (const gsd::LogArray* b = log(f, i, kBoxDouble, 1, 6))
      std::copy(b->values.begin(), b->values.end(), box.begin());
    else
      std::copy(f.box.begin(), f.box.end(), box.begin());
    for (double v : box)
      if (!std::isfinite(v)) fail(i, "the box has a non-finite entry");
    const auto [Lx, Ly, Lz, xy, xz, yz] = box;
    const std::array<double, 9> lattice{Lx, 0.0, 0.0, xy * Ly, Ly, 0.0, xz * Lz, yz * Lz, Lz};
    std::array<double, 3> origin{};
    if (opt_.origin) {
      origin = *opt_.origin;
    } else if (const gsd::LogArray* o = log(f, i, kBoxOrigin, 1, 3)) {
      std::copy(o->values.begin(), o->values.end(), origin.begin());
    } else {
      for (int k = 0; k < 3; ++k) origin[k] = -0.5 * (lattice[k] + lattice[3 + k] + lattice[6 + k]);
    }

    // Species names and semi-axes per type.
    const std::size_t nt = f.types.size();
    std::vector<std::array<double, 3>> axes(nt, {0.0, 0.0, 0.0});
    for (std::size_t t = 0; t < nt; ++t) {
      const std::string& name = f.types[t];
      if (name.empty() || std::any_of(name.begin(), name.end(), [](unsigned char c) {
            return std::isspace(c) || c == '"' || c < 0x20;
          }))
        fail(i, fmt::format("type name '{}' cannot be an XYZ species (empty, or has blanks or quotes)",
                            name));
      std::optional<std::array<double, 3>> a;
      try {
        if (t < f.type_shapes.size()) a = known_semi_axes(f.type_shapes[t]);
      } catch (const std::invalid_argument& e) {
        fail(i, fmt::format("type '{}': {}", name, e.what()));
      }
      if (a) {
        axes[t] = *a;
      } else if (!opt_.allow_unknown_shapes) {
        fail(i, t < f.type_shapes.size()
                    ? fmt::format("type '{}': no bounding semi-axes for shape {} (allow unknown "
                                  "shapes to write 0 0 0)", name, f.type_shapes[t])
                    : fmt::format("type '{}' has no type_shapes entry (allow unknown shapes to "
                                  "write 0 0 0)", name));
      }
    }

    const Column pos = column(f, i, kPositionDouble, f.position, 3);
    const Column quat = column(f, i, kOrientationDouble, f.orientation, 4);
    const Column vel = column(f, i, kVelocityDouble, f.velocity, 3);
    if (f.type_id.size() != f.N) fail(i, "typeid has the wrong length");

    fmt::format_to(std::back_inserter(out), "{}\nLattice=\"{}\" Origin=\"{}\" Properties={} pbc=\"T T T\"",
                   f.N, fmt::join(lattice, " "), fmt::join(origin, " "), kProperties);
    if (const gsd::LogArray* t = log(f, i, kTime, 1, 1))
      fmt::format_to(std::back_inserter(out), " Time={}", t->values[0]);
    fmt::format_to(std::back_inserter(out), " Step={}\n", f.step);

    constexpr std::array<int, 4> xyz{0, 1, 2, 0};
    constexpr std::array<int, 4> xyzw{1, 2, 3, 0};  // GSD [w, x, y, z] -> OVITO x y z w
    for (std::size_t p = 0; p < f.N; ++p) {
      const std::uint32_t t = f.type_id[p];
      out += f.types[t];
      pos.put_row(out, p, xyz, 3);
      quat.put_row(out, p, xyzw, 4);
      for (double a : axes[t]) put(out, a);
      vel.put_row(out, p, xyz, 3);
      out += '\n';
    }
  }

 private:
  std::string path_;
  const ConvertOptions& opt_;
};

// The temporary output file: removed on destruction unless committed.
class TempOutput {
 public:
  explicit TempOutput(std::string final_path)
      : final_(std::move(final_path)), tmp_(final_ + ".tmp") {
    file_ = std::fopen(tmp_.c_str(), "wb");
    if (!file_)
      throw std::runtime_error(fmt::format("{}: cannot write: {}", tmp_, std::strerror(errno)));
  }
  ~TempOutput() {
    if (file_) std::fclose(file_);
    if (!committed_) std::remove(tmp_.c_str());
  }
  TempOutput(const TempOutput&) = delete;
  TempOutput& operator=(const TempOutput&) = delete;

  void write(const std::string& s) {
    if (std::fwrite(s.data(), 1, s.size(), file_) != s.size())
      throw std::runtime_error(fmt::format("{}: write failed: {}", tmp_, std::strerror(errno)));
  }
  void commit() {
    const bool ok = std::fflush(file_) == 0 && ::fsync(::fileno(file_)) == 0;
    const int err = errno;
    const bool closed = std::fclose(file_) == 0;
    file_ = nullptr;
    if (!ok || !closed)
      throw std::runtime_error(fmt::format("{}: write failed: {}", tmp_, std::strerror(ok ? errno : err)));
    if (std::rename(tmp_.c_str(), final_.c_str()) != 0)
      throw std::runtime_error(
          fmt::format("{}: cannot rename into place: {}", final_, std::strerror(errno)));
    committed_ = true;
  }

 private:
  std::string final_;
  std::string tmp_;
  std::FILE* file_ = nullptr;
  bool committed_ = false;
};

}  // namespace

std::array<double, 3> shape_semi_axes(const std::string& type_shape_json) {
  if (auto a = known_semi_axes(type_shape_json)) return *a;
  throw std::invalid_argument(
      fmt::format("no bounding semi-axes for shape {}", type_shape_json));
}

void convert_gsd_to_xyz(const std::string& gsd_path, const std::string& out_path,
                        const ConvertOptions& options) {
  std::error_code ec;
  if (std::filesystem::equivalent(gsd_path, out_path, ec))
    throw std::runtime_error(
        fmt::format("{}: the output file would replace the input trajectory", out_path));
  if (options.stride == 0)
    throw std::runtime_error(fmt::format("{}: frame stride must be at least 1", gsd_path));

  const gsd::Reader reader(gsd_path);  // throws "<path>: ..." for a missing or corrupt file
  const std::uint64_t n = reader.nframes();
  const std::uint64_t end = options.end.value_or(n);
  if (n == 0) throw std::runtime_error(fmt::format("{}: the file has no frames", gsd_path));
  if (end > n || options.first >= end)
    throw std::runtime_error(fmt::format("{}: frame range [{}, {}) is empty or outside the {} "
                                         "frames of the file",
                                         gsd_path, options.first, end, n));

  const Converter conv(gsd_path, options);
  TempOutput out(out_path);
  std::string text;
  for (std::uint64_t i = options.first; i < end; i = end - i > options.stride ? i + options.stride : end) {
    text.clear();
    conv.format_frame(gsd::read_frame(reader, i), i, text);
    out.write(text);
  }
  out.commit();
}

}  // namespace hb
