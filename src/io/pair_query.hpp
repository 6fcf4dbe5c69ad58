// `hardbody distance` and `hardbody contact-time`: JSON lines in, JSON lines out (DESIGN.md
// contract). One pair per input line; a malformed line stops with InputError naming the line.
#pragma once
#include <istream>
#include <ostream>
#include <string>

namespace hb {

// Returns the number of pairs processed. `source` names the input in error messages.
std::size_t distance_queries(std::istream& in, std::ostream& out, const std::string& source);
std::size_t contact_time_queries(std::istream& in, std::ostream& out, const std::string& source,
                                 double eps_d = 1e-5);

}  // namespace hb
