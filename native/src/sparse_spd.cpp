#include "sparse_spd.hpp"

#include <chrono>

#include <Eigen/SparseCholesky>
#ifdef RELIEF_SNAKE_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

namespace relief_snake {

namespace {

template <class Solver, class Scalar>
bool factor_and_solve(Solver& solver, const Eigen::SparseMatrix<Scalar>& A,
                      const Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& B,
                      Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>* X, SpdTimings* timings) {
  using Clock = std::chrono::steady_clock;
  auto lap = [](Clock::time_point* since) {
    const Clock::time_point now = Clock::now();
    const double seconds = std::chrono::duration<double>(now - *since).count();
    *since = now;
    return seconds;
  };
  SpdTimings t;
  Clock::time_point mark = Clock::now();
  solver.analyzePattern(A);
  t.ordering = lap(&mark);
  bool ok = solver.info() == Eigen::Success;
  if (ok) {
    solver.factorize(A);
    t.factorisation = lap(&mark);
    ok = solver.info() == Eigen::Success;
  }
  if (ok) {
    *X = solver.solve(B);
    t.solve = lap(&mark);
    ok = solver.info() == Eigen::Success && X->allFinite();
  }
  if (timings) {
    timings->ordering += t.ordering;
    timings->factorisation += t.factorisation;
    timings->solve += t.solve;
  }
  return ok;
}

/// Eigen's SimplicialLDLT with its AMD ordering, the permutation computed from A's own pattern. A
/// stores both triangles, sorted: the very pattern SimplicialLDLT<..., AMDOrdering> rebuilds before
/// the same minimum degree routine (mirroring the lower triangle, then forming A + A^T), and it
/// permutes A again in factorize(). Here A is permuted once, for both steps. Same permutation, same
/// factor, same solution, bit for bit.
template <class Scalar>
bool ldlt_solve(const Eigen::SparseMatrix<Scalar>& A, const Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& B,
                Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>* X, SpdTimings* timings) {
  using Clock = std::chrono::steady_clock;
  using Matrix = Eigen::SparseMatrix<Scalar>;
  using Permutation = Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int>;
  const Clock::time_point start = Clock::now();
  Permutation inverse;  // new position -> old, as AMDOrdering gives it
  {
    Matrix pattern = A;  // the minimum degree routine works in its argument
    Eigen::internal::minimum_degree_ordering(pattern, inverse);
  }
  const Permutation permutation = inverse.inverse();
  Matrix permuted(A.rows(), A.cols());
  permuted.template selfadjointView<Eigen::Upper>() = A.template selfadjointView<Eigen::Lower>().twistedBy(permutation);
  Eigen::SimplicialLDLT<Matrix, Eigen::Upper, Eigen::NaturalOrdering<int>> ldlt;
  const double permuting = std::chrono::duration<double>(Clock::now() - start).count();
  const Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> permuted_right = permutation * B;
  Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic> permuted_solution;
  const bool ok = factor_and_solve(ldlt, permuted, permuted_right, &permuted_solution, timings);
  if (timings) timings->ordering += permuting;
  if (!ok) return false;
  *X = inverse * permuted_solution;
  return X->allFinite();
}

template <class Scalar>
bool solve_positive_definite(const Eigen::SparseMatrix<Scalar>& A,
                             const Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>& B,
                             Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>* X, SpdTimings* timings) {
  if (timings) *timings = SpdTimings();
#ifdef RELIEF_SNAKE_HAVE_CHOLMOD
  {
    Eigen::CholmodDecomposition<Eigen::SparseMatrix<Scalar>, Eigen::Lower> cholmod;
    if (factor_and_solve(cholmod, A, B, X, timings)) return true;
  }
  // CHOLMOD's LL^T refuses a matrix that is only semidefinite in floating point; LDL^T may not.
#endif
  return ldlt_solve(A, B, X, timings);
}

}  // namespace

bool solve_spd(const Eigen::SparseMatrix<double>& A, const Eigen::MatrixXd& B, Eigen::MatrixXd* X,
               SpdTimings* timings) {
  return solve_positive_definite(A, B, X, timings);
}

bool solve_hpd(const Eigen::SparseMatrix<std::complex<double>>& A, const Eigen::MatrixXcd& B, Eigen::MatrixXcd* X,
               SpdTimings* timings) {
  return solve_positive_definite(A, B, X, timings);
}

const char* spd_solver_name() {
#ifdef RELIEF_SNAKE_HAVE_CHOLMOD
  return "cholmod";
#else
  return "eigen-simplicial-ldlt";
#endif
}

}  // namespace relief_snake
