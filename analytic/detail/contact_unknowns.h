// The bound on the contact problems' unknowns and their fixed-capacity matrices, shared by the force solve (contact_dynamics.cpp) and the impact solve (contact_impacts.cpp).
#pragma once

#include <Eigen/Dense>

namespace tippe::contact_detail {

// 2 contacts x (normal + 2 tangential + drilling): the force solve has at most 8 unknowns, an
// impact at most 7. Matrices of that capacity live on the stack: no allocation per evaluation.
constexpr int kMaxUnknowns = 8;
using MatN = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, 0, kMaxUnknowns, kMaxUnknowns>;
using VecN = Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMaxUnknowns, 1>;

}  // namespace tippe::contact_detail
