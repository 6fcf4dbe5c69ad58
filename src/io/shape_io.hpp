// Shapes in the JSON and GSD formats, through the registry's codec entries (shapes/codec.hpp):
// the `hardbody distance` / `contact-time` input, summary.json, and GSD `type_shapes`.
#pragma once
#include <functional>
#include <string>

#include <nlohmann/json.hpp>

#include "shapes/registry.hpp"

namespace hb {

// {"type": NAME, params...} -> shape. `fail(message)` reports a problem (it must throw);
// messages read "shape: key 'semi_axes': every semi-axis must be positive".
AnyShape shape_from_json(const nlohmann::json& j, const std::function<void(const std::string&)>& fail);
// The same object back (full precision).
nlohmann::json shape_to_json(const AnyShape& s);
// The GSD `particles/type_shapes` entry (HOOMD shape specification) of the shape.
std::string gsd_type_shape(const AnyShape& s);

}  // namespace hb
