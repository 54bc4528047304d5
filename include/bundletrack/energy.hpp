#pragma once

#include <span>
#include <tuple>

#include <opencv2/core.hpp>

#include "bundletrack/residuals/pair_system.hpp"

namespace bundletrack {

/// One weighted term of the pose-graph energy (paper eq. 1): a residual, its robust loss and lambda.
template <Residual ResidualT, RobustLoss LossT>
struct Term {
  using ResidualType = ResidualT;
  using LossType = LossT;
  ResidualT residual{};
  LossT loss{};
  double weight = 1.0;
};

namespace detail {

/// One term over every edge: in one call when its residual is a BatchResidual, else edge by edge
/// in parallel.
template <typename TermT>
void lineariseTerm(const TermT& term, std::span<const PairInput> inputs, std::span<PairSystem> systems) {
  if constexpr (BatchResidual<typename TermT::ResidualType>) {
    term.residual.lineariseAll(inputs, term.loss, term.weight, systems);
  } else {
    cv::parallel_for_(cv::Range(0, int(inputs.size())), [&](const cv::Range& range) {
      for (int e = range.start; e < range.end; ++e)
        term.residual.linearise(inputs[std::size_t(e)], term.loss, term.weight, systems[std::size_t(e)]);
    });
  }
}

}  // namespace detail

/// The energy as a compile-time list of terms, e.g.
///   Energy<Term<FeaturePointToPoint, HuberLoss>, Term<DensePointToPlane, HuberLoss>>
/// A feature-only tracker simply leaves the dense term out.
template <typename... Terms>
struct Energy {
  std::tuple<Terms...> terms;

  void linearise(const PairInput& input, PairSystem& system) const {
    std::apply([&](const auto&... term) { (term.residual.linearise(input, term.loss, term.weight, system), ...); },
               terms);
  }

  /// Every edge of a graph: systems[e] gets what linearise(inputs[e], systems[e]) adds, term by
  /// term in the same order.
  void lineariseAll(std::span<const PairInput> inputs, std::span<PairSystem> systems) const {
    std::apply([&](const auto&... term) { (detail::lineariseTerm(term, inputs, systems), ...); }, terms);
  }
};

template <typename T>
concept PoseGraphEnergy = requires(const T& energy, const PairInput& input, PairSystem& system) {
  { energy.linearise(input, system) } -> std::same_as<void>;
};

}  // namespace bundletrack
