#pragma once
// The regions from hull-edge lines solved by the caller (region_tangents.hpp), so that an
// object's inner and outer lines are solved together (compute_object_regions).
#include <span>

#include "covtrack/client/regions.hpp"
#include "region_tangents.hpp"

namespace covtrack::client {

// contract_region, from the hull's inner lines.
void contract_region(std::span<const ProjectedVertex> hull, std::span<const TangentLine> inner_lines,
                     Polygon& inner);

// expand_region, from the mean hull's outer lines (empty: none solved, so the search),
// solved with the confidence scale squared `s2` (the ellipses here take the same).
void expand_region(std::span<const ProjectedVertex> vertices, std::span<const int> mean_hull,
                   std::span<const TangentLine> outer_lines, double s2, const RegionOptions& o,
                   Polygon& outer);

}  // namespace covtrack::client
