// Exact sums added over the ranks: the same double on any rank count (core/exact_sum), for the
// rows of histories.csv.  Messages carry O(sums) words, never O(ranks) or O(model).
#pragma once

#include <vector>

#include "core/exact_sum.hpp"
#include "parallel/communicator.hpp"

namespace fdem {

// Collective: on rank 0, sums[i] becomes the sum of every rank's sums[i] (the same count on every
// rank); on the other ranks it is left partial.  A binomial tree: log2(ranks) rounds of one
// message, each the words of the sums (ExactSum::append_words).
void reduce_exact_sums_to_root(std::vector<ExactSum>& sums, const Communicator& comm);

}  // namespace fdem
