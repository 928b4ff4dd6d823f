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
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<Scalar>> ldlt;
  return factor_and_solve(ldlt, A, B, X, timings);
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
