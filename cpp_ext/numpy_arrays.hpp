// What the binding files share: a std::vector as a new numpy array.
#ifndef NGFRACTURE_NUMPY_ARRAYS_HPP
#define NGFRACTURE_NUMPY_ARRAYS_HPP
#include <python_comp.hpp>
#include <algorithm>
#include <vector>

namespace ngfracture
{
  // v as a 1D array (width 1) or as rows of ``width`` entries
  template <typename T>
  pybind11::array_t<T> ToNumpy (const std::vector<T> & v, size_t width = 1)
  {
    size_t h = width ? v.size() / width : 0;
    pybind11::array_t<T> out = width == 1 ? pybind11::array_t<T>(h) : pybind11::array_t<T>({ h, width });
    std::copy(v.begin(), v.end(), out.mutable_data());
    return out;
  }
}
#endif
