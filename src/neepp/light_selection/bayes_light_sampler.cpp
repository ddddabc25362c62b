#include "neepp/light_selection/bayes_light_sampler.h"

#include <algorithm>
#include <cmath>
#include <queue>
#include <stdexcept>
#include "neepp/io/binary_io.h"

namespace neepp {

namespace {
constexpr char kMagic[8] = {'N', 'E', 'E', 'P', 'P', 'B', 'L', '1'};
}  // namespace

BayesLightSampler::BayesLightSampler(std::vector<const Light *> lights, const VoxelGrid &grid, BayesSelectionOptions options)
    : options_(options), bvh_(lights), keys_(grid, options.oriented), learned_(keys_.count()),
      pending_(new std::atomic<PendingStats *>[keys_.count()]), tables_(keys_.count()) {
    if (!(options_.epsilon > 0 && options_.epsilon <= 1))
        throw std::invalid_argument("the defensive fraction must be in (0, 1]: a light with zero probability would bias the image");
    if (options_.cut_size < 1) throw std::invalid_argument("the light cut needs at least one node");
    if (!(options_.alpha0 > 1 && options_.beta0 > 0 && options_.kappa0 > 0 && options_.a0 > 0 && options_.b0 > 0))
        throw std::invalid_argument("the Bayesian light sampler's prior must be proper (alpha0 > 1, the rest > 0)");
    for (uint32_t k = 0; k < keys_.count(); ++k) pending_[k].store(nullptr, std::memory_order_relaxed);
    uint32_t max_index = 0;
    for (const Light *l : lights) max_index = std::max(max_index, l->index);
    slot_of_light_.assign(lights.empty() ? 0 : max_index + 1, -1);
    build_cut();
    std::vector<int32_t> slot_of_node(bvh_.node_count(), -1);
    for (size_t j = 0; j < cut_.size(); ++j) slot_of_node[cut_[j].node] = int32_t(j);
    for (const Light *l : lights) {  // the one cut node on each light's path from the root
        const BVHLightSampler::Trail t = bvh_.trail(*l);
        if (t.length < 0) continue;
        uint32_t node = 0;
        for (int d = 0; slot_of_node[node] < 0; ++d) node = (t.bits >> d) & 1 ? bvh_.second_child(node) : node + 1;
        slot_of_light_[l->index] = slot_of_node[node];
    }
}

BayesLightSampler::~BayesLightSampler() {
    for (uint32_t k = 0; k < keys_.count(); ++k) delete[] pending_[k].load(std::memory_order_relaxed);
}

void BayesLightSampler::build_cut() {
    // Split the most powerful node until the cut has cut_size nodes or only leaves: resolution where the
    // power is. The order of the cut is by node index, so it is a pure function of the tree.
    if (bvh_.node_count() == 0) return;
    auto weaker = [&](const CutNode &a, const CutNode &b) {
        return bvh_.node_power(a.node) < bvh_.node_power(b.node) ||
               (bvh_.node_power(a.node) == bvh_.node_power(b.node) && a.node > b.node);
    };
    std::priority_queue<CutNode, std::vector<CutNode>, decltype(weaker)> open(weaker);
    open.push({0, 0, 0});
    std::vector<CutNode> done;
    while (!open.empty() && done.size() + open.size() < size_t(options_.cut_size)) {
        const CutNode c = open.top();
        open.pop();
        if (bvh_.is_leaf(c.node) || c.depth >= 63) {
            done.push_back(c);
            continue;
        }
        open.push({c.node + 1, c.depth + 1, c.bits});
        open.push({bvh_.second_child(c.node), c.depth + 1, c.bits | (uint64_t(1) << c.depth)});
    }
    for (; !open.empty(); open.pop()) done.push_back(open.top());
    std::sort(done.begin(), done.end(), [](const CutNode &a, const CutNode &b) { return a.node < b.node; });
    cut_ = std::move(done);
}

std::vector<double> BayesLightSampler::prior(uint32_t key) const {
    // The BVH's own choice of each cut node from the record's voxel centre, facing the record's
    // orientation, plus a share by power (the centre is not where the shading points are).
    const VoxelGrid &grid = keys_.grid();
    int x, y, z;
    grid.voxel_coords(keys_.voxel(key), x, y, z);
    const Vec3 size = grid.bounds().extent() / float(grid.resolution());
    LightSampleContext centre{grid.bounds().lo + Vec3((float(x) + 0.5f) * size.x, (float(y) + 0.5f) * size.y,
                                                      (float(z) + 0.5f) * size.z),
                              Vec3(0.f)};
    if (const uint32_t b = keys_.bucket(key); b != kNoOrientation) centre.n[int(b / 2)] = b % 2 ? -1.f : 1.f;
    const size_t K = cut_.size();
    std::vector<double> bvh(K), power(K);
    double bvh_total = 0, power_total = 0;
    for (size_t j = 0; j < K; ++j) {
        bvh_total += bvh[j] = bvh_.descent_probability(0, 0, cut_[j].depth, cut_[j].bits, centre);
        power_total += power[j] = bvh_.node_power(cut_[j].node);
    }
    const double share = bvh_total > 0 ? options_.prior_power_share : 1.0;
    std::vector<double> p(K);
    for (size_t j = 0; j < K; ++j)
        p[j] = (1 - share) * (bvh_total > 0 ? bvh[j] / bvh_total : 0.0) + share * power[j] / power_total;
    return p;
}

std::unique_ptr<float[]> BayesLightSampler::build_table(uint32_t key) const {
    const size_t K = cut_.size();
    const std::vector<double> p0 = prior(key);
    static const std::vector<NodeStats> none;
    const std::vector<NodeStats> &stats = learned_[key].empty() ? none : learned_[key];
    auto at = [&](size_t j) { return stats.empty() ? NodeStats{} : stats[j]; };
    // The prior's log-mean per node: log p0 plus the record's mean log-ratio of what was seen to p0, so the
    // prior speaks the data's units (empirical Bayes) and, with nothing seen, is proportional to p0.
    double offset = 0, seen = 0;
    for (size_t j = 0; j < K; ++j) {
        const NodeStats s = at(j);
        offset += double(s.log_sum) / kLogScale - double(s.contributing) * std::log(p0[j]);
        seen += double(s.contributing);
    }
    if (seen > 0) offset /= seen;
    const double k0 = options_.kappa0, al0 = options_.alpha0, be0 = options_.beta0;
    std::vector<double> logw(K);
    for (size_t j = 0; j < K; ++j) {
        const NodeStats s = at(j);
        const double m0 = std::log(p0[j]) + offset;
        const double n = double(s.contributing);
        double mean = m0, kappa = k0, alpha = al0, beta = be0;
        if (n > 0) {  // the normal-gamma posterior of the log-contributions
            const double ybar = double(s.log_sum) / kLogScale / n;
            const double ss = std::max(0.0, double(s.log_square_sum) / (kLogScale * kLogScale) - n * ybar * ybar);
            kappa = k0 + n;
            mean = (k0 * m0 + n * ybar) / kappa;
            alpha = al0 + n / 2;
            beta = be0 + ss / 2 + k0 * n * (ybar - m0) * (ybar - m0) / (2 * kappa);
        }
        // Expected variance of a log-contribution, with the mean's own uncertainty; capped, since the
        // lognormal's moments grow as exp(σ²) and a few outliers would otherwise hand a node everything.
        const double var = std::min(beta / (alpha - 1) * (1 + 1 / kappa), 4.0);
        const double visible = (n + options_.a0) / (double(s.samples) + options_.a0 + options_.b0);
        logw[j] = options_.second_moment ? 0.5 * std::log(visible) + mean + var  // √(E[V]·E[x²])
                                         : std::log(visible) + mean + 0.5 * var;  // E[V]·E[x]
    }
    const double top = *std::max_element(logw.begin(), logw.end());
    std::vector<double> w(K);
    double total = 0;
    for (size_t j = 0; j < K; ++j) total += w[j] = std::exp(logw[j] - top);
    // The defensive share is the prior itself, whose power part is > 0 for every node: a node the record
    // learned nothing good of keeps a probability, and every light its descent can reach with it.
    auto t = std::make_unique<float[]>(2 * K);
    double running = 0;
    for (size_t j = 0; j < K; ++j) {
        const double p = (1 - options_.epsilon) * w[j] / total + options_.epsilon * p0[j];
        t[j] = float(p);
        running += p;
        t[K + j] = j + 1 == K ? 1.f : float(running);
    }
    return t;
}

const float *BayesLightSampler::table(uint32_t key) const {
    return tables_.get(key, [this](uint32_t k) { return build_table(k); });
}

float BayesLightSampler::node_probability(const LightSampleContext &ctx, size_t slot) const {
    return table(keys_.of(ctx))[slot];
}

SampledLight BayesLightSampler::sample(const LightSampleContext &ctx, float u) const {
    const float p_inf = bvh_.infinite_probability();
    if (u < p_inf) {  // as the BVH does
        const auto &inf = bvh_.infinite_lights();
        u = std::min(u / p_inf, kOneMinusEpsilon);
        const size_t i = std::min(size_t(u * float(inf.size())), inf.size() - 1);
        return {inf[i], p_inf / float(inf.size())};
    }
    if (cut_.empty()) return {};
    u = std::min((u - p_inf) / (1 - p_inf), kOneMinusEpsilon);
    const float *t = table(keys_.of(ctx));
    const size_t K = cut_.size();
    const size_t j = std::min(size_t(std::upper_bound(t + K, t + 2 * K, u) - (t + K)), K - 1);
    if (!(t[j] > 0)) return {};
    const float lo = j == 0 ? 0.f : t[K + j - 1];
    const SampledLight s = bvh_.sample_below(cut_[j].node, ctx, std::clamp((u - lo) / t[j], 0.f, kOneMinusEpsilon));
    if (!s.light) return {};
    // The descent below the node multiplied the same branch probabilities in the same order as pmf()'s
    // descent_probability does, so s.pmf is pmf()'s `below` to the bit and need not be walked again.
    return {s.light, mix(p_inf, s.pmf, t[j])};
}

float BayesLightSampler::pmf(const LightSampleContext &ctx, const Light &light) const {
    const BVHLightSampler::Trail t = bvh_.trail(light);
    const float p_inf = bvh_.infinite_probability();
    if (t.infinite) return p_inf / float(bvh_.infinite_lights().size());
    if (t.length < 0 || light.index >= slot_of_light_.size() || slot_of_light_[light.index] < 0) return 0.f;
    const size_t j = size_t(slot_of_light_[light.index]);
    const CutNode &c = cut_[j];
    const float below = bvh_.descent_probability(c.node, c.depth, t.length, t.bits, ctx);
    if (!(below > 0)) return 0.f;
    return mix(p_inf, below, table(keys_.of(ctx))[j]);
}

BayesLightSampler::PendingStats *BayesLightSampler::pending(uint32_t key) const {
    if (PendingStats *p = pending_[key].load(std::memory_order_acquire)) return p;
    auto fresh = std::make_unique<PendingStats[]>(cut_.size());
    PendingStats *expected = nullptr;
    if (pending_[key].compare_exchange_strong(expected, fresh.get(), std::memory_order_acq_rel)) return fresh.release();
    return expected;  // another thread made it first
}

void BayesLightSampler::record(const LightSampleContext &ctx, const Light &light, float estimate) const {
    if (light.index >= slot_of_light_.size() || slot_of_light_[light.index] < 0 || !(estimate >= 0)) return;
    const size_t j = size_t(slot_of_light_[light.index]);
    const CutNode &c = cut_[j];
    const BVHLightSampler::Trail t = bvh_.trail(light);
    // The estimate of the whole node's contribution this light sample makes: divided by the probability
    // the plain descent below the node gives the light.
    const float below = bvh_.descent_probability(c.node, c.depth, t.length, t.bits, ctx);
    if (!(below > 0)) return;
    PendingStats &s = pending(keys_.of(ctx))[j];
    s.samples.fetch_add(1, std::memory_order_relaxed);
    const double x = double(estimate) / double(below);
    if (!(x > 0) || !std::isfinite(x)) return;
    const int64_t q = std::llround(std::clamp(std::log(x), -80.0, 80.0) * kLogScale);
    s.contributing.fetch_add(1, std::memory_order_relaxed);
    s.log_sum.fetch_add(q, std::memory_order_relaxed);
    s.log_square_sum.fetch_add(q * q, std::memory_order_relaxed);
}

void BayesLightSampler::end_pass() {
    const size_t K = cut_.size();
    for (uint32_t k = 0; k < keys_.count(); ++k) {
        PendingStats *p = pending_[k].load(std::memory_order_relaxed);
        if (!p) continue;
        if (learned_[k].empty()) learned_[k].resize(K);
        for (size_t j = 0; j < K; ++j) {
            NodeStats &l = learned_[k][j];
            l.samples += p[j].samples.exchange(0, std::memory_order_relaxed);
            l.contributing += p[j].contributing.exchange(0, std::memory_order_relaxed);
            l.log_sum += p[j].log_sum.exchange(0, std::memory_order_relaxed);
            l.log_square_sum += p[j].log_square_sum.exchange(0, std::memory_order_relaxed);
        }
    }
    samples_learned_ = 0;
    for (const auto &r : learned_)
        for (const NodeStats &s : r) samples_learned_ += s.samples;
    tables_.clear();
    ++passes_;
}

std::string BayesLightSampler::format(const Learned &learned, uint32_t keys, uint32_t cut) {
    BinaryWriter w;
    w.bytes.append(kMagic, sizeof kMagic);
    w.put(keys);
    w.put(cut);
    for (uint32_t k = 0; k < keys; ++k) {
        if (learned[k].empty()) continue;
        w.put(k);
        for (const NodeStats &s : learned[k]) w.put(s);
    }
    return w.bytes;
}

BayesLightSampler::Learned BayesLightSampler::parse(const std::string &state, uint32_t &keys, uint32_t &cut) {
    BinaryReader r{state, 0, "Bayesian light sampler state"};
    r.need(sizeof kMagic);
    if (state.compare(0, sizeof kMagic, kMagic, sizeof kMagic) != 0) throw std::runtime_error(r.what + ": not one");
    r.pos = sizeof kMagic;
    keys = r.get<uint32_t>();
    cut = r.get<uint32_t>();
    Learned out(keys);
    while (r.pos < state.size()) {
        const uint32_t k = r.get<uint32_t>();
        if (k >= keys || !out[k].empty()) throw std::runtime_error(r.what + ": bad record");
        r.need(size_t(cut) * sizeof(NodeStats));
        out[k].resize(cut);
        for (NodeStats &s : out[k]) s = r.get<NodeStats>();
    }
    return out;
}

std::string BayesLightSampler::save_state() const { return format(learned_, keys_.count(), uint32_t(cut_.size())); }

void BayesLightSampler::restore_state(const std::string &state) {
    uint32_t keys = keys_.count(), cut = uint32_t(cut_.size());
    Learned learned = state.empty() ? Learned(keys) : parse(state, keys, cut);
    if (keys != keys_.count() || cut != cut_.size())
        throw std::runtime_error("Bayesian light sampler state: saved for another grid or light cut");
    learned_ = std::move(learned);
    for (uint32_t k = 0; k < keys_.count(); ++k)
        if (PendingStats *p = pending_[k].load(std::memory_order_relaxed))
            for (size_t j = 0; j < cut_.size(); ++j) p[j].samples = p[j].contributing = 0, p[j].log_sum = p[j].log_square_sum = 0;
    tables_.clear();
}

// What each render learned beyond the base, added up: the sums are integers, so the merge is exact and
// depends on nothing but the states (it needs no sampler: distributed rendering merges before any scene).
std::string BayesLightSampler::merge_encoded(const std::string &base, const std::vector<std::string> &learned) {
    if (learned.empty()) return base;
    uint32_t keys = 0, cut = 0;
    std::vector<Learned> parts;
    for (const std::string &state : learned) {
        if (state.empty()) continue;  // a render whose sampler did not learn (a scene with one light)
        uint32_t k = 0, c = 0;
        parts.push_back(parse(state, k, c));
        if (parts.size() > 1 && (k != keys || c != cut)) throw std::runtime_error("Bayesian light sampler states: of different grids");
        keys = k, cut = c;
    }
    if (parts.empty()) return base;
    Learned b(keys);
    if (!base.empty()) {
        uint32_t k = 0, c = 0;
        b = parse(base, k, c);
        if (k != keys || c != cut) throw std::runtime_error("Bayesian light sampler states: of different grids");
    }
    Learned merged = b;
    for (const Learned &l : parts)
        for (uint32_t k = 0; k < keys; ++k) {
            if (l[k].empty()) continue;
            if (merged[k].empty()) merged[k].resize(cut);
            for (size_t j = 0; j < cut; ++j) {
                const NodeStats from = b[k].empty() ? NodeStats{} : b[k][j];
                NodeStats &m = merged[k][j];
                m.samples += l[k][j].samples - from.samples;
                m.contributing += l[k][j].contributing - from.contributing;
                m.log_sum += l[k][j].log_sum - from.log_sum;
                m.log_square_sum += l[k][j].log_square_sum - from.log_square_sum;
            }
        }
    return format(merged, keys, cut);
}

nlohmann::json BayesLightSampler::statistics() const {
    uint64_t records = 0;
    for (const auto &r : learned_) records += r.empty() ? 0 : 1;
    nlohmann::json s = bvh_.statistics();
    s["cut_size"] = cut_.size();
    s["epsilon"] = options_.epsilon;
    s["second_moment"] = options_.second_moment;
    s["oriented"] = keys_.oriented();
    s["records_learned"] = records;
    s["samples_learned"] = samples_learned_;
    s["tables_built"] = tables_.built();  // over all passes
    s["passes"] = passes_;
    return s;
}

}  // namespace neepp
