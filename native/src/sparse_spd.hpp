#pragma once
// One sparse symmetric (or Hermitian) positive definite solve, shared by the background fill
// (background.cpp, real) and the conformal flattening (height_map.cpp, complex): CHOLMOD from
// SuiteSparse (which picks supernodal or simplicial and the AMD or METIS ordering itself) when the
// build has it (CMake option RELIEF_SNAKE_WITH_CHOLMOD), else Eigen's SimplicialLDLT.
#include <complex>

#include <Eigen/Dense>
#include <Eigen/Sparse>

namespace relief_snake {

/// Where one solve_spd() spent its time (wall seconds; for the stages' reports and benchmarks).
struct SpdTimings {
  double ordering = 0;       ///< fill-reducing ordering and symbolic analysis
  double factorisation = 0;  ///< numeric factorisation
  double solve = 0;          ///< triangular solves for every column of B
};

/// X (#A by #B cols) = A^-1 B for A (n by n, symmetric positive definite; both triangles
/// stored) and B (n by k): one factorisation for all k columns. False if the factorisation or
/// the solve fails or X is not finite. timings, if given, gets the stages' times (summed over
/// the attempts when CHOLMOD falls back to LDL^T).
bool solve_spd(const Eigen::SparseMatrix<double>& A, const Eigen::MatrixXd& B, Eigen::MatrixXd* X,
               SpdTimings* timings = nullptr);

/// The same for a Hermitian positive definite A (both triangles stored) and complex B: the
/// least-squares conformal map's normal equations, n complex unknowns instead of 2n real ones
/// (a quarter of the factor's entries).
bool solve_hpd(const Eigen::SparseMatrix<std::complex<double>>& A, const Eigen::MatrixXcd& B, Eigen::MatrixXcd* X,
               SpdTimings* timings = nullptr);

/// "cholmod" or "eigen-simplicial-ldlt": which solver this build uses (for benchmarks and notes).
const char* spd_solver_name();

}  // namespace relief_snake
