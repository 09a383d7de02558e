// The samples of one type in a mixed sample list (tests of the phonesim transforms).
#pragma once
#include <variant>
#include <vector>

#include "pdnav/geo/samples.h"

namespace pdnav::test {

template <typename S>
std::vector<S> only(const std::vector<Sample>& in) {
  std::vector<S> out;
  for (const Sample& s : in)
    if (const auto* x = std::get_if<S>(&s)) out.push_back(*x);
  return out;
}

}  // namespace pdnav::test
