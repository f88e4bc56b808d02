// What the bindings of the 3D contact kernels share: the numpy array types they take
// (C order, converted if needed) and the checks of their arguments, whose errors name the
// function and the argument.
#ifndef NGFRACTURE_BINDING_CHECKS_HPP
#define NGFRACTURE_BINDING_CHECKS_HPP
#include <python_comp.hpp>
#include <algorithm>
#include <cstdint>
#include <stdexcept>
#include <string>

namespace ngfracture::bindings
{
  using DArr = pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast>;
  using LArr = pybind11::array_t<int64_t, pybind11::array::c_style | pybind11::array::forcecast>;

  // a has ndim dimensions, ``cols`` columns if it has two, and ``rows`` rows unless -1
  inline void Check (const char * fn, const char * name, const pybind11::array & a, int ndim, pybind11::ssize_t cols,
                     pybind11::ssize_t rows = -1)
  {
    if (a.ndim() != ndim || (ndim == 2 && a.shape(1) != cols) || (rows >= 0 && a.shape(0) != rows))
      throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " has the wrong shape");
  }

  // every entry of a in [lo, bound)
  inline void CheckRange (const char * fn, const char * name, const LArr & a, int64_t bound, int64_t lo = 0)
  {
    // one pass without an early exit or compares (the check runs on every call of the
    // round's kernels, over arrays as long as the boundary's faces): with q = p - lo
    // (unsigned, wrapping), the sign bit of q is set for p < lo, that of (bound - 1 - lo) - q
    // for p >= bound, so the or of both over all entries has its top bit set exactly if an
    // entry is outside (subtractions and ors, which vectorise without 64-bit compares)
    const uint64_t * p = reinterpret_cast<const uint64_t *>(a.data());
    const uint64_t shift = uint64_t(lo), last = uint64_t(bound) - 1 - shift;
    const pybind11::ssize_t n = a.size();      // out of the loop: a call into numpy
    uint64_t out = 0;
    for (pybind11::ssize_t i = 0; i < n; i++)
      {
        const uint64_t q = p[i] - shift;
        out |= q | (last - q);
      }
    if (out >> 63)
      throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " has an entry outside ["
                                  + std::to_string(lo) + ", " + std::to_string(bound) + ")");
  }

  // the number of reference points the vertices of a reach (largest point + 1), every one on
  // a point (point[v] >= 0); a's entries in range
  inline int64_t PointCount (const char * fn, const char * name, const LArr & a, const LArr & point)
  {
    int64_t count = 0;
    const int64_t * v = a.data(), * pid = point.data();
    for (pybind11::ssize_t i = 0, n = a.size(); i < n; i++)
      {
        const int64_t q = pid[v[i]];
        if (q < 0)
          throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name
                                      + " has a vertex of no point (point -1)");
        count = std::max(count, q + 1);
      }
    return count;
  }

  // a 1D array whose entries do not decrease
  inline void CheckSorted (const char * fn, const char * name, const LArr & a)
  {
    const int64_t * p = a.data();
    const pybind11::ssize_t n = a.size();
    for (pybind11::ssize_t i = 1; i < n; i++)
      if (p[i] < p[i - 1])
        throw std::invalid_argument(std::string("ngfracture.") + fn + ": " + name + " is not sorted");
  }
}
#endif
