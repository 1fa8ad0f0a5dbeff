// The cache's second-order terms (internal, not installed): the Hessian fit that
// cache_irradiance runs after placement and fit_record_hessians (cache.hpp) exposes.
#pragma once

#include "hemilight/cache.hpp"

#include <vector>

namespace hemilight::cache_detail {

// Fits every record's `hessian` from the records around it (fit_record_hessians in cache.hpp
// states the rule); records are not checked. `threads`: the cores it may use (the result is the
// same for any count). Cost: O(records x neighbours).
void fit_hessians(std::vector<cache_record>& records, const cache_options& o, int threads);

}  // namespace hemilight::cache_detail
