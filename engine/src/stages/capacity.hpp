// Capacity of the arrays that grow with the scene's contacts: grown by a quarter rather
// than doubled, and given back once use falls far below it, so that the memory a space
// holds follows its contacts instead of their high-water mark. Both are rare (the gap
// between the two thresholds): a step that changes little allocates nothing.
#pragma once

#include <algorithm>
#include <cstddef>
#include <iterator>
#include <vector>

namespace spindle {

// Room for at least `needed` elements.
template <typename T>
void reserve_for(std::vector<T>& v, std::size_t needed) {
    if (v.capacity() < needed) v.reserve(std::max(needed, v.capacity() + v.capacity() / 4));
}

// Whether a capacity is far enough above its use to give back: over twice the use, and
// more than a few elements (small arrays are not worth the move). The gap between this
// and fit_capacity's quarter to spare is what keeps a count that swings from step to
// step (a tumbling pile's contacts) from moving its arrays every step.
inline bool far_above_use(std::size_t capacity, std::size_t size) {
    constexpr std::size_t kMinExcess = 64;
    return capacity > 2 * size + kMinExcess;
}

// Moves the elements into an array with a quarter to spare.
template <typename T>
void fit_capacity(std::vector<T>& v) {
    std::vector<T> fitted;
    fitted.reserve(v.size() + v.size() / 4);
    std::move(v.begin(), v.end(), std::back_inserter(fitted));
    v.swap(fitted);
}

}  // namespace spindle
