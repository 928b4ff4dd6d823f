#include "sparse_spd.hpp"

#include <Eigen/SparseCholesky>
#ifdef RELIEF_SNAKE_HAVE_CHOLMOD
#include <Eigen/CholmodSupport>
#endif

namespace relief_snake {

namespace {

template <class Solver>
bool factor_and_solve(Solver& solver, const Eigen::SparseMatrix<double>& A, const Eigen::MatrixXd& B,
                      Eigen::MatrixXd* X) {
  solver.compute(A);
  if (solver.info() != Eigen::Success) return false;
  *X = solver.solve(B);
  return solver.info() == Eigen::Success && X->allFinite();
}

}  // namespace

bool solve_spd(const Eigen::SparseMatrix<double>& A, const Eigen::MatrixXd& B, Eigen::MatrixXd* X) {
#ifdef RELIEF_SNAKE_HAVE_CHOLMOD
  {
    Eigen::CholmodDecomposition<Eigen::SparseMatrix<double>, Eigen::Lower> cholmod;
    if (factor_and_solve(cholmod, A, B, X)) return true;
  }
  // CHOLMOD's LL^T refuses a matrix that is only semidefinite in floating point; LDL^T may not.
#endif
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> ldlt;
  return factor_and_solve(ldlt, A, B, X);
}

const char* spd_solver_name() {
#ifdef RELIEF_SNAKE_HAVE_CHOLMOD
  return "cholmod";
#else
  return "eigen-simplicial-ldlt";
#endif
}

}  // namespace relief_snake
