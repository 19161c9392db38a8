#pragma once
// Tiny fixed-size 3x3 algebra usable on host and device (no Eigen in kernels).
#include <cmath>

#include "sim/core/sim_hd.h"

namespace softtled {

template <class T>
struct Mat3 {
  T m[3][3];
  SIM_HD T& operator()(int r, int c) { return m[r][c]; }
  SIM_HD const T& operator()(int r, int c) const { return m[r][c]; }
};

template <class T>
SIM_HD inline Mat3<T> identity3() {
  Mat3<T> a{};
  a(0, 0) = a(1, 1) = a(2, 2) = T(1);
  return a;
}

template <class T>
SIM_HD inline T det3(const Mat3<T>& a) {
  return a(0, 0) * (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) -
         a(0, 1) * (a(1, 0) * a(2, 2) - a(1, 2) * a(2, 0)) +
         a(0, 2) * (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0));
}

// cof(a) = det(a) a^-T, defined for any a (also singular or inverted).
template <class T>
SIM_HD inline Mat3<T> cofactor3(const Mat3<T>& F) {
  Mat3<T> c;
  c(0, 0) = F(1, 1) * F(2, 2) - F(1, 2) * F(2, 1);
  c(0, 1) = F(1, 2) * F(2, 0) - F(1, 0) * F(2, 2);
  c(0, 2) = F(1, 0) * F(2, 1) - F(1, 1) * F(2, 0);
  c(1, 0) = F(0, 2) * F(2, 1) - F(0, 1) * F(2, 2);
  c(1, 1) = F(0, 0) * F(2, 2) - F(0, 2) * F(2, 0);
  c(1, 2) = F(0, 1) * F(2, 0) - F(0, 0) * F(2, 1);
  c(2, 0) = F(0, 1) * F(1, 2) - F(0, 2) * F(1, 1);
  c(2, 1) = F(0, 2) * F(1, 0) - F(0, 0) * F(1, 2);
  c(2, 2) = F(0, 0) * F(1, 1) - F(0, 1) * F(1, 0);
  return c;
}

// Inverse of any invertible matrix given its determinant: the adjugate cof(a)^T times
// 1/det, written out (general, not only symmetric input).
template <class T>
SIM_HD inline Mat3<T> inverse3(const Mat3<T>& a, T det) {
  Mat3<T> r;
  const T id = T(1) / det;
  r(0, 0) = (a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1)) * id;
  r(0, 1) = (a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2)) * id;
  r(0, 2) = (a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1)) * id;
  r(1, 0) = (a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2)) * id;
  r(1, 1) = (a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0)) * id;
  r(1, 2) = (a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2)) * id;
  r(2, 0) = (a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0)) * id;
  r(2, 1) = (a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1)) * id;
  r(2, 2) = (a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)) * id;
  return r;
}

template <class T>
SIM_HD inline Mat3<T> mul(const Mat3<T>& a, const Mat3<T>& b) {
  Mat3<T> r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = a(i, 0) * b(0, j) + a(i, 1) * b(1, j) + a(i, 2) * b(2, j);
  return r;
}

template <class T>
SIM_HD inline Mat3<T> transpose_mul(const Mat3<T>& a, const Mat3<T>& b) {  // a^T b
  Mat3<T> r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = a(0, i) * b(0, j) + a(1, i) * b(1, j) + a(2, i) * b(2, j);
  return r;
}

}  // namespace softtled
