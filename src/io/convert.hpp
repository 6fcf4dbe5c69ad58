// `hardbody convert trajectory.gsd --to xyz`: a hoomd-schema GSD trajectory -> one extended-XYZ
// file (OVITO's dialect) with box, species, position, orientation, shape and velocity. See
// docs/convert.md for the format and for opening the result in OVITO.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>

namespace hb {

struct ConvertOptions {
  // Frames [first, end) with step `stride`; end = nullopt means "to the last frame".
  std::uint64_t first = 0;
  std::optional<std::uint64_t> end;
  std::uint64_t stride = 1;
  // Lower corner of the box, written as Origin="x y z". Precedence: this value, then the
  // frame's log chunk `log/hardbody/box_origin` (1 x 3 float64), then the HOOMD convention of a
  // box centred on 0, i.e. -(a1 + a2 + a3) / 2.
  std::optional<std::array<double, 3>> origin;
  // A type whose type_shapes entry is missing or of a kind without a known bounding box gets
  // aspherical_shape 0 0 0 (OVITO then draws its default sphere) instead of an error.
  bool allow_unknown_shapes = false;
};

// Semi-axes (a, b, c) for the aspherical_shape column from one GSD type_shapes JSON entry:
// Sphere d/2 d/2 d/2; Ellipsoid a b c; ConvexPolyhedron / ConvexSpheropolyhedron the half
// extents of the body-frame box |v|max per axis, plus the rounding radius; SphereUnion likewise
// over its spheres. Throws std::invalid_argument for malformed JSON, a non-positive or
// non-finite size, or another shape type.
std::array<double, 3> shape_semi_axes(const std::string& type_shape_json);

// Converts frames of `gsd_path` into the extended-XYZ file `out_path`, one block per frame:
//   N
//   Lattice="a1 a2 a3" Origin="o" Properties=species:S:1:pos:R:3:orientation:R:4:
//     aspherical_shape:R:3:velo:R:3 pbc="T T T" [Time=t] Step=s
//   <type> x y z qx qy qz qw a b c vx vy vz          (N lines)
// The orientation is written in OVITO's order x y z w (GSD stores w x y z). Positions,
// orientations and velocities come from the log chunks `particles/hardbody/position_double`,
// `orientation_double`, `velocity_double` when present, else from the float32 chunks; the box
// from `log/hardbody/box_double` (1 x 6) if present, else `configuration/box`; Time from
// `log/hardbody/time`. Every number is written with the shortest text that reads back to the
// same double (or float, for float32 data), i.e. without loss.
// The output is written to out_path + ".tmp" and renamed into place: on any error no output
// (and no temporary) file is left and an existing out_path is unchanged.
// Throws std::runtime_error naming the file for a missing or corrupt GSD file, a frame range
// outside the file, a malformed chunk, an unusable shape or type name, or an I/O failure.
void convert_gsd_to_xyz(const std::string& gsd_path, const std::string& out_path,
                        const ConvertOptions& options = {});

}  // namespace hb
