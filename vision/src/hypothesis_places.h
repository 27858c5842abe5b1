#pragma once
// Which of detection's scored candidates become hypotheses (detector.cpp, stage 2): the best,
// shared out over the template distances. A near template's long outline laid on dense texture
// outscores the object's own at its distance, and without the share such candidates take every
// place. Header-only: a template over the caller's test of "lies on a kept one".
#include <algorithm>
#include <cstddef>
#include <vector>

namespace epichead::vision::detail {

// Candidates are indexed best first; distance_of[i] is candidate i's distance index (0 ...
// distances - 1). Returns the indices kept, at most `places`: a first pass keeps at most
// ceil(places / distances) per distance, a second fills what is left with the best of the rest.
// `lies_on_kept(i)` is asked before keeping i (the caller remembers what it kept: it is kept
// exactly when this returns false); a candidate for which it is true is skipped and takes no place.
template <class LiesOnKept>
std::vector<std::size_t> hypothesis_places(const std::vector<int>& distance_of, int distances, int places, LiesOnKept&& lies_on_kept) {
  std::vector<std::size_t> kept;
  if (places <= 0) return kept;
  const int n = std::max(1, distances);
  const int per_distance = (places + n - 1) / n;  // >= 1, since places >= 1
  std::vector<int> taken(static_cast<std::size_t>(n), 0);
  std::vector<char> seen(distance_of.size(), 0);
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t i = 0; i < distance_of.size() && static_cast<int>(kept.size()) < places; ++i) {
      const auto d = static_cast<std::size_t>(std::clamp(distance_of[i], 0, n - 1));
      if (seen[i] || (pass == 0 && taken[d] >= per_distance)) continue;
      seen[i] = 1;
      if (lies_on_kept(i)) continue;
      ++taken[d];
      kept.push_back(i);
    }
  return kept;
}

}  // namespace epichead::vision::detail
