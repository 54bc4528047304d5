#pragma once

#include <span>
#include <tuple>
#include <utility>
#include <vector>

#include "bundletrack/core/execution.hpp"
#include "bundletrack/graph/edge_linearisation_cache.hpp"
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
  /// input of each edge, taken from the graph once. With an enabled EdgeLinearisationCache, edges
  /// between two of the pool's keyframes (graph.pool_indices) take their system from it while it
  /// is fresh enough, and leave it there when they are linearised.
  class Problem {
   public:
    Problem(const Energy& energy, const PoseGraph& graph, EdgeLinearisationCache* kept = nullptr)
        : energy_(energy), edges_(graph.edges), kept_(kept != nullptr && kept->enabled() ? kept : nullptr) {
      bindInputs(graph, std::index_sequence_for<Terms...>());
      if (kept_ == nullptr) return;
      const auto in_pool = [&](int node) { return std::size_t(node) < graph.pool_indices.size(); };
      for (const GraphEdge& edge : edges_)
        keys_.push_back(in_pool(edge.i) && in_pool(edge.j)
                            ? std::pair{graph.nodes[std::size_t(edge.i)]->id, graph.nodes[std::size_t(edge.j)]->id}
                            : std::pair{-1, -1});
    }

    std::span<const GraphEdge> edges() const { return edges_; }

    /// systems[e] gets edge e's residuals of every term, term by term in list order (or the
    /// cache's system of the edge, moved to `poses`).
    void linearise(std::span<const SE3d> poses, std::span<PairSystem> systems) const {
      if (kept_ == nullptr) {
        lineariseTerms(edges_, inputs_, poses, systems, std::index_sequence_for<Terms...>());
        return;
      }
      const auto pose = [&](int node) -> const SE3d& { return poses[std::size_t(node)]; };
      std::vector<std::size_t> fresh;
      for (std::size_t e = 0; e < edges_.size(); ++e) {
        const auto [a, b] = keys_[e];
        if (a < 0 || !kept_->reuse(a, b, pose(edges_[e].i), pose(edges_[e].j), systems[e])) fresh.push_back(e);
      }
      std::vector<GraphEdge> edges;
      Inputs inputs;  // of the fresh edges only
      for (const std::size_t e : fresh) {
        edges.push_back(edges_[e]);
        appendInputs(inputs, e, std::index_sequence_for<Terms...>());
      }
      std::vector<PairSystem> linearised(fresh.size());
      lineariseTerms(edges, inputs, poses, linearised, std::index_sequence_for<Terms...>());
      for (std::size_t k = 0; k < fresh.size(); ++k) {
        const std::size_t e = fresh[k];
        systems[e] = linearised[k];
        if (const auto [a, b] = keys_[e]; a >= 0) kept_->keep(a, b, pose(edges_[e].i), pose(edges_[e].j), linearised[k]);
      }
    }

   private:
    using Inputs = std::tuple<std::vector<typename Terms::ResidualType::Input>...>;

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
    void appendInputs(Inputs& inputs, std::size_t e, std::index_sequence<K...>) const {
      (std::get<K>(inputs).push_back(std::get<K>(inputs_)[e]), ...);
    }

    template <std::size_t... K>
    void lineariseTerms(std::span<const GraphEdge> edges, const Inputs& inputs, std::span<const SE3d> poses,
                        std::span<PairSystem> systems, std::index_sequence<K...>) const {
      (lineariseTerm(std::get<K>(energy_.terms), edges, std::get<K>(inputs), poses, systems), ...);
    }
    /// One term over the edges: in one call when its residual is a BatchResidual, else edge by edge.
    template <typename TermT, typename TermInputs>
    void lineariseTerm(const TermT& term, std::span<const GraphEdge> edges, const TermInputs& inputs,
                       std::span<const SE3d> poses, std::span<PairSystem> systems) const {
      if constexpr (BatchResidual<typename TermT::ResidualType>) {
        term.residual.lineariseAll(std::span(inputs), edges, poses, term.loss, term.weight, systems);
      } else {
        forEachIndex(energy_.execution, int(edges.size()), [&](int e) {
          const GraphEdge& edge = edges[std::size_t(e)];
          term.residual.linearise(inputs[std::size_t(e)], poses[std::size_t(edge.i)], poses[std::size_t(edge.j)], term.loss,
                                  term.weight, systems[std::size_t(e)]);
        });
      }
    }

    const Energy& energy_;
    std::vector<GraphEdge> edges_;
    Inputs inputs_;
    EdgeLinearisationCache* kept_;  ///< null: every edge linearised every step
    std::vector<std::pair<int, int>> keys_;  ///< per edge: its keyframes' ids, {-1, -1} for an edge to the current frame
  };

  Problem over(const PoseGraph& graph, EdgeLinearisationCache* kept = nullptr) const { return Problem(*this, graph, kept); }

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
