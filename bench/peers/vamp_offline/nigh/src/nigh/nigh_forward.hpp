// cellplan bench/peers: a stand-in for the parts of Kavraki Lab's `nigh` nearest-neighbour
// library that VAMP 0.6.4 uses (vamp/planning/nn.hh). VAMP's build fetches nigh from GitHub,
// which this machine cannot reach, so bench/peers/vamp_offline/build.sh builds VAMP against this
// header instead. Written for cellplan; it is NOT nigh's code and not its algorithm: a linear
// scan over coordinates copied at insertion (nigh uses a batched k-d tree). Results are the
// same nearest neighbours (ties aside); only the time of a query on a large tree differs.
#pragma once

#include <algorithm>
#include <cstddef>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

namespace unc::robotics::nigh
{
    namespace metric
    {
        template <int p>
        struct LP
        {
        };

        // VAMP specialises Space<NNFloatArray<dim>, LP<2>> with Type, Distance, kDimensions,
        // coeff(v, i) and distance(a, b).
        template <typename Type, typename Metric>
        struct Space;
    }  // namespace metric

    struct NoThreadSafety
    {
    };

    template <std::size_t batchSize = 128>
    struct KDTreeBatch
    {
    };

    template <typename T, typename Space, typename KeyFn, typename Concurrency, typename Strategy>
    class Nigh
    {
        using Key = typename Space::Type;
        using Distance = typename Space::Distance;
        static constexpr std::size_t kDim = static_cast<std::size_t>(Space::kDimensions);

        std::vector<T> nodes_;
        std::vector<float> coords_;  // kDim floats per node, in insertion order
        KeyFn keyFn_{};

        auto squared(const float *q, std::size_t i) const noexcept -> float
        {
            const float *c = coords_.data() + i * kDim;
            float s = 0.0F;
            for (std::size_t d = 0; d < kDim; ++d)
            {
                const float e = c[d] - q[d];
                s += e * e;
            }
            return s;
        }

        void load(const Key &key, float *q) const noexcept
        {
            for (std::size_t d = 0; d < kDim; ++d)
            {
                q[d] = static_cast<float>(Space::coeff(key, d));
            }
        }

    public:
        void insert(const T &t)
        {
            nodes_.push_back(t);
            const auto &key = keyFn_(t);
            for (std::size_t d = 0; d < kDim; ++d)
            {
                coords_.push_back(static_cast<float>(Space::coeff(key, d)));
            }
        }

        [[nodiscard]] auto size() const noexcept -> std::size_t
        {
            return nodes_.size();
        }

        void clear() noexcept
        {
            nodes_.clear();
            coords_.clear();
        }

        // The nearest node and its distance (Space::distance), or nothing when empty.
        auto nearest(const Key &key) const -> std::optional<std::pair<T, Distance>>
        {
            if (nodes_.empty())
            {
                return std::nullopt;
            }
            float q[kDim];
            load(key, q);
            std::size_t best = 0;
            float bestSq = std::numeric_limits<float>::infinity();
            for (std::size_t i = 0; i < nodes_.size(); ++i)
            {
                const float s = squared(q, i);
                if (s < bestSq)
                {
                    bestSq = s;
                    best = i;
                }
            }
            return std::make_pair(nodes_[best], static_cast<Distance>(Space::distance(keyFn_(nodes_[best]), key)));
        }

        // Up to k nearest nodes within maxRadius, nearest first, into result (cleared first).
        template <typename Tuple>
        void nearest(std::vector<Tuple> &result, const Key &key, std::size_t k, Distance maxRadius) const
        {
            result.clear();
            if (k == 0 or nodes_.empty())
            {
                return;
            }
            float q[kDim];
            load(key, q);
            const float r2 = static_cast<float>(maxRadius) * static_cast<float>(maxRadius);
            std::vector<std::pair<float, std::size_t>> found;
            for (std::size_t i = 0; i < nodes_.size(); ++i)
            {
                const float s = squared(q, i);
                if (s <= r2)
                {
                    found.emplace_back(s, i);
                }
            }
            const std::size_t n = std::min(k, found.size());
            std::partial_sort(found.begin(), found.begin() + n, found.end());
            result.reserve(n);
            for (std::size_t j = 0; j < n; ++j)
            {
                const T &node = nodes_[found[j].second];
                result.emplace_back(node, static_cast<Distance>(Space::distance(keyFn_(node), key)));
            }
        }
    };
}  // namespace unc::robotics::nigh
