#include "compute/ReducedArap.h"

namespace plano::compute {

std::unique_ptr<ReducedArapKernels> Backend::createReducedArapKernels(
    const std::function<ReducedArapProblem()>& problem) {
  (void)problem;  // no device kernels: the algorithm's host kernels run
  return nullptr;
}

}  // namespace plano::compute
