#pragma once

#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "bundletrack/core/execution.hpp"
#include "bundletrack/graph/pose_graph.hpp"
#include "bundletrack/residuals/residual.hpp"
#include "bundletrack/solvers/pose_graph_problem.hpp"

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

/// The energy as a compile-time list of terms, e.g.
///   Energy<Term<FeaturePointToPoint, HuberLoss>, Term<DensePointToPlane, HuberLoss>>
/// A feature-only tracker simply leaves the dense term out; a new term is a Residual and one more
/// Term in the list.
template <typename... Terms>
struct Energy {
  std::tuple<Terms...> terms;
  Execution execution = Execution::Parallel;  ///< edges of a term linearise in parallel or one by one

  /// The energy over one pose graph, ready for Gauss-Newton (a PoseGraphProblem): each term's
  /// input of each edge, taken from the graph once.
  class Problem {
   public:
    Problem(const Energy& energy, const PoseGraph& graph) : energy_(energy), edges_(graph.edges) {
      bindInputs(graph, std::index_sequence_for<Terms...>());
    }

    std::span<const GraphEdge> edges() const { return edges_; }

    /// systems[e] gets edge e's residuals of every term, term by term in list order.
    void linearise(std::span<const SE3d> poses, std::span<PairSystem> systems) const {
      lineariseTerms(poses, systems, std::index_sequence_for<Terms...>());
    }

   private:
    template <std::size_t... K>
    void bindInputs(const PoseGraph& graph, std::index_sequence<K...>) {
      (bindTerm<K>(graph), ...);
    }
    template <std::size_t K>
    void bindTerm(const PoseGraph& graph) {
      using R = typename std::tuple_element_t<K, std::tuple<Terms...>>::ResidualType;
      auto& inputs = std::get<K>(inputs_);
      inputs.reserve(edges_.size());
      for (std::size_t e = 0; e < edges_.size(); ++e) inputs.push_back(R::input(graph.edge(e)));
    }

    template <std::size_t... K>
    void lineariseTerms(std::span<const SE3d> poses, std::span<PairSystem> systems, std::index_sequence<K...>) const {
      (lineariseTerm(std::get<K>(energy_.terms), std::get<K>(inputs_), poses, systems), ...);
    }
    /// One term over every edge: in one call when its residual is a BatchResidual, else edge by edge.
    template <typename TermT, typename Inputs>
    void lineariseTerm(const TermT& term, const Inputs& inputs, std::span<const SE3d> poses,
                       std::span<PairSystem> systems) const {
      if constexpr (BatchResidual<typename TermT::ResidualType>) {
        term.residual.lineariseAll(std::span(inputs), edges(), poses, term.loss, term.weight, systems);
      } else {
        forEachIndex(energy_.execution, int(edges_.size()), [&](int e) {
          const GraphEdge& edge = edges_[std::size_t(e)];
          term.residual.linearise(inputs[std::size_t(e)], poses[std::size_t(edge.i)], poses[std::size_t(edge.j)], term.loss,
                                  term.weight, systems[std::size_t(e)]);
        });
      }
    }

    const Energy& energy_;
    std::vector<GraphEdge> edges_;
    std::tuple<std::vector<typename Terms::ResidualType::Input>...> inputs_;
  };

  Problem over(const PoseGraph& graph) const { return Problem(*this, graph); }

  /// Whether a term of non-zero weight reads the keyframes' intensity images (its residual says
  /// so: `static constexpr bool kReadsImages = true`); without one the tracker builds none.
  bool readsImages() const {
    return std::apply([](const Terms&... term) { return (... || (readsImagesOf<typename Terms::ResidualType> && term.weight != 0.0)); },
                      terms);
  }

  /// Likewise for the keyframes' silhouette images (`kReadsSilhouettes`).
  bool readsSilhouettes() const {
    return std::apply(
        [](const Terms&... term) { return (... || (readsSilhouettesOf<typename Terms::ResidualType> && term.weight != 0.0)); }, terms);
  }

 private:
  template <typename R>
  static constexpr bool readsImagesOf = requires { requires R::kReadsImages; };
  template <typename R>
  static constexpr bool readsSilhouettesOf = requires { requires R::kReadsSilhouettes; };
};

/// What the tracker asks of its energy: a Gauss-Newton problem over each frame's pose graph.
template <typename T>
concept PoseGraphEnergy = requires(const T& energy, const PoseGraph& graph) {
  { energy.over(graph) } -> PoseGraphProblem;
};

}  // namespace bundletrack
