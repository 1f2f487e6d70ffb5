#pragma once
// Eigen's dense decompositions of Eigen::MatrixXd, instantiated once, in the library
// (src/continuation/eigen_instances.cpp), instead of in every source file that uses one: a
// divide-and-conquer SVD is among the costliest templates to compile at -O3. Only a build-time matter:
// the precompiled headers (cmake/precompiled_headers.cmake) include this file, so every source of
// a target linking buckle::continuation calls the library's copies; without it each file
// instantiates its own, with the same code.
#include <Eigen/Dense>
#include <Eigen/Eigenvalues>

extern template class Eigen::BDCSVD<Eigen::MatrixXd>;
extern template class Eigen::JacobiSVD<Eigen::MatrixXd>;
extern template class Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>;
extern template class Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd>;
extern template class Eigen::EigenSolver<Eigen::MatrixXd>;
extern template class Eigen::FullPivLU<Eigen::MatrixXd>;
extern template class Eigen::PartialPivLU<Eigen::MatrixXd>;
extern template class Eigen::HouseholderQR<Eigen::MatrixXd>;
extern template class Eigen::ColPivHouseholderQR<Eigen::MatrixXd>;
extern template class Eigen::LLT<Eigen::MatrixXd>;
extern template class Eigen::LDLT<Eigen::MatrixXd>;
