#include "neepp/guiding/map_guide.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>
#include "neepp/io/binary_io.h"
#include "neepp/visibility/visibility_map.h"

namespace neepp {

namespace {

constexpr char kMagic[8] = {'N', 'E', 'E', 'P', 'P', 'M', 'G', '1'};
constexpr uint64_t kSaturate = uint64_t(1) << 62;

// v · 2^exponent as an integer, saturating; what is not a finite number >= 0 counts as 0.
uint64_t fixed(double v, int exponent) {
    if (!(v > 0) || !std::isfinite(v)) return 0;
    const double x = std::ldexp(v, exponent);
    return x < double(kSaturate) ? uint64_t(x) : kSaturate;
}

// A direction bin's patch spans 2/S of its cube face along each side, so a direction drawn uniformly on
// the patch has area density (S/2)² on the face at distance 1, and solid-angle density (S/2)² · r³ with
// r = 1 / max|d_k| the distance to the face along unit d.
float bin_density(const Vec3 &d) {
    constexpr float S = float(VoxelGrid::kDirectionBinsPerFaceSide);
    const float m = std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)});
    return m > 0 ? (S * 0.5f) * (S * 0.5f) / (m * m * m) : 0.f;
}

// Where the ray p + t·d, t >= 0, crosses the box: [t0, t1], false if it misses it.
bool chord(const BBox &b, const Vec3 &p, const Vec3 &d, float &t0, float &t1) {
    t0 = 0.f;
    t1 = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (d[a] != 0.f) {
            const float ta = (b.lo[a] - p[a]) / d[a], tb = (b.hi[a] - p[a]) / d[a];
            t0 = std::max(t0, std::min(ta, tb));
            t1 = std::min(t1, std::max(ta, tb));
        } else if (p[a] < b.lo[a] || p[a] > b.hi[a]) {
            return false;
        }
    }
    return t0 < t1;
}

}  // namespace

MapGuide::MapGuide(const VoxelGrid &grid, MapGuideOptions options)
    : grid_(grid), options_(options), cell_size_(grid.bounds().extent() / float(grid.resolution())),
      voxels_(grid.voxel_count()), locks_(new std::mutex[kStripes]), bound_locks_(new std::mutex[kStripes]),
      seen_(grid.voxel_count()) {
    set_boxes();
}

void MapGuide::record(const Vec3 &p, uint32_t target, double flux, double radiance, const Vec3 &end) {
    const uint32_t i = grid_.voxel_of(p);
    {
        Voxel &v = voxels_[i];
        std::lock_guard<std::mutex> lock(locks_[i % kStripes]);
        ++v.pass_samples;
        if (target == kNoTarget || target >= grid_.cell_count()) return;
        Acc &a = v.pass[target];
        a.flux += fixed(flux, scale_exponent_);
        a.radiance += fixed(radiance, scale_exponent_);
        ++a.count;
    }
    // One lock at a time (never the target's while holding the voxel's): no order between them to deadlock.
    if (!grid_.is_direction_cell(target) && is_finite(end)) {
        std::lock_guard<std::mutex> lock(bound_locks_[target % kStripes]);
        seen_[target].expand(end);
    }
}

void MapGuide::set_boxes() {
    boxes_.resize(grid_.voxel_count());
    inv_volume_.resize(grid_.voxel_count());
    const Vec3 e = cell_size_;
    for (uint32_t j = 0; j < grid_.voxel_count(); ++j) {
        int x, y, z;
        grid_.voxel_coords(j, x, y, z);
        BBox voxel;
        voxel.lo = grid_.bounds().lo + Vec3(float(x), float(y), float(z)) * e;
        voxel.hi = voxel.lo + e;
        BBox b = voxel;
        if (seen_[j].valid()) {
            b = seen_[j];
            for (int a = 0; a < 3; ++a) {
                // At least a twentieth of the voxel thick, moved inside it.
                const float want = 0.05f * e[a], have = b.hi[a] - b.lo[a];
                if (have < want) {
                    b.lo[a] -= 0.5f * (want - have);
                    b.hi[a] = b.lo[a] + want;
                }
                if (b.lo[a] < voxel.lo[a]) b.hi[a] = std::min(voxel.hi[a], b.hi[a] + (voxel.lo[a] - b.lo[a])), b.lo[a] = voxel.lo[a];
                if (b.hi[a] > voxel.hi[a]) b.lo[a] = std::max(voxel.lo[a], b.lo[a] - (b.hi[a] - voxel.hi[a])), b.hi[a] = voxel.hi[a];
            }
        }
        boxes_[j] = b;
        const Vec3 ext = b.extent();
        inv_volume_[j] = float(1.0 / (double(ext.x) * ext.y * ext.z));
    }
}

void MapGuide::update(const VisibilityMap *map) {
    // The pass's sums join the totals. Each (voxel, target) total receives one addition per pass, so the
    // order of this loop changes nothing.
    unsigned __int128 flux = 0;  // exact, whatever the order
    uint64_t records = 0;
    for (Voxel &v : voxels_) {
        for (const auto &[target, a] : v.pass) {
            Total &t = v.total[target];
            t.flux += std::ldexp(double(a.flux), -scale_exponent_);
            t.radiance += std::ldexp(double(a.radiance), -scale_exponent_);
            t.count += a.count;
            flux += a.flux;
        }
        v.samples += v.pass_samples;
        records += v.pass_samples;
        v.pass.clear();
        v.pass_samples = 0;
    }
    records_ += records;
    set_boxes();
    // The next pass's fixed-point scale: ~2^24 steps below the mean record, a power of two (exact).
    if (records > 0 && flux > 0) {
        const double mean = std::ldexp(double(flux), -scale_exponent_) / double(records);
        scale_exponent_ = std::clamp(24 - int(std::ceil(std::log2(mean))), -60, 60);
    }
    build_tables(map);
}

void MapGuide::build_tables(const VisibilityMap *map) {
    tables_.clear();
    table_of_voxel_.assign(grid_.voxel_count(), -1);
    const uint32_t cells = grid_.cell_count();
    // What each cell sends out: the mean radiance of the recorded rays that ended in it.
    std::vector<double> radiance(cells, 0.0);
    std::vector<uint64_t> count(cells, 0);
    for (const Voxel &v : voxels_)
        for (const auto &[target, t] : v.total) {
            radiance[target] += t.radiance;
            count[target] += t.count;
        }
    std::vector<uint32_t> bright;
    for (uint32_t j = 0; j < cells; ++j)
        if (count[j] > 0 && radiance[j] > 0) {
            radiance[j] /= double(count[j]);
            bright.push_back(j);
        } else {
            radiance[j] = 0;
        }
    // The voxels that get a table: the most-recorded ones, as many as the memory bound allows.
    std::vector<uint32_t> order;
    for (uint32_t i = 0; i < grid_.voxel_count(); ++i)
        if (voxels_[i].samples > 0) order.push_back(i);
    const size_t per_table = size_t(cells) * sizeof(float) * 2;
    const size_t most = std::max<size_t>(1, options_.max_table_bytes / per_table);
    if (order.size() > most) {
        std::stable_sort(order.begin(), order.end(),
                         [&](uint32_t a, uint32_t b) { return voxels_[a].samples > voxels_[b].samples; });
        order.resize(most);
        std::sort(order.begin(), order.end());
    }
    const Vec3 e = cell_size_;
    // A voxel's solid angle from a distance d: its mean projected area (a quarter of its surface, for a
    // convex body) over d², at most a hemisphere; a direction bin: its share of the sphere.
    const double mean_area = 0.5 * (double(e.x) * e.y + double(e.y) * e.z + double(e.z) * e.x);
    const double bin_solid_angle = 4.0 * M_PI / VoxelGrid::kDirectionBins;
    const double k = options_.prior_records;
    auto center = [&](uint32_t cell) {
        int x, y, z;
        grid_.voxel_coords(cell, x, y, z);
        return grid_.bounds().lo + Vec3(float(x) + 0.5f, float(y) + 0.5f, float(z) + 0.5f) * e;
    };
    std::vector<Vec3> bright_center(bright.size());
    for (size_t b = 0; b < bright.size(); ++b)
        if (!grid_.is_direction_cell(bright[b])) bright_center[b] = center(bright[b]);
    // A table's weights are sparse (its targets and the bright cells its voxel has traced to): only the
    // cells touched are visited, in ascending order, so that every sum adds what the dense loop over all
    // cells added (zeros leave a sum unchanged) and the tables are the same to the bit.
    std::vector<double> w(cells, 0.0);
    std::vector<uint32_t> touched;
    for (uint32_t i : order) {
        const Voxel &v = voxels_[i];
        const double n = double(v.samples);
        touched.clear();
        // Learned: the summed flux from each target (n times the mean flux estimate).
        for (const auto &[target, t] : v.total) {
            w[target] += t.flux / (n + k);
            touched.push_back(target);
        }
        if (map && k > 0) {
            const Vec3 ci = center(i);
            for (size_t b = 0; b < bright.size(); ++b) {
                const uint32_t j = bright[b];
                // Pairs the map has traced only: its 1/2 for an unknown pair would send the prior to every
                // bright voxel behind every wall.
                const PairCounts c = map->counts(i, j);
                if (c.traced == 0) continue;
                double solid_angle = bin_solid_angle;
                if (!grid_.is_direction_cell(j)) {
                    const double d2 = double(squared_norm(bright_center[b] - ci));
                    solid_angle = d2 > 0 ? std::min(2.0 * M_PI, mean_area / d2) : 2.0 * M_PI;
                }
                w[j] += k * double(VisibilityMap::estimate(c)) * radiance[j] * solid_angle / (n + k);
                touched.push_back(j);
            }
        }
        std::sort(touched.begin(), touched.end());
        touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
        double sum = 0;
        for (uint32_t j : touched) sum += w[j];
        if (!(sum > 0) || !std::isfinite(sum)) {
            for (uint32_t j : touched) w[j] = 0.0;
            continue;
        }
        Table t;
        t.pmf.assign(cells, 0.f);
        double running = 0;
        for (uint32_t j : touched) {
            const float p = float(w[j] / sum);
            w[j] = 0.0;  // ready for the next table
            if (!(p > 0)) continue;
            t.pmf[j] = p;
            running += double(p);
            t.cells.push_back(j);
            t.cdf.push_back(float(running));
        }
        if (t.cells.empty()) continue;
        // The float pmf sums to `running`, not exactly 1: scale both so that density and sampling agree.
        const float scale = float(1.0 / running);
        for (float &p : t.pmf) p *= scale;
        for (float &c : t.cdf) c *= scale;
        t.cdf.back() = 1.f;
        table_of_voxel_[i] = int32_t(tables_.size());
        tables_.push_back(std::move(t));
    }
}

Vec3 MapGuide::sample(const Table &t, const Vec3 &p, float u_cell, float u1, Vec2 u2) const {
    const size_t at = std::min<size_t>(size_t(std::upper_bound(t.cdf.begin(), t.cdf.end(), u_cell) - t.cdf.begin()),
                                       t.cells.size() - 1);
    const uint32_t j = t.cells[at];
    if (grid_.is_direction_cell(j)) return grid_.direction_in_bin(j, u2);
    const BBox &b = boxes_[j];
    const Vec3 target = b.lo + Vec3(u1, u2.x, u2.y) * b.extent();
    const Vec3 d = target - p;
    const float len = norm(d);
    return len > 0 && std::isfinite(len) ? d / len : Vec3(0.f);
}

float MapGuide::pdf(const Table &t, const Vec3 &p, const Vec3 &d) const {
    return t.pmf[grid_.cell_of_direction(d)] * bin_density(d) + voxel_part(t, p, d);
}

// A uniform point of a box of volume V seen from p: along unit d the ray crosses the box over [t0, t1],
// and the direction's solid-angle density is ∫ t² dt / V = (t1³ - t0³) / 3V. Summed over the target boxes
// of the voxels the ray from p crosses (a 3D DDA through the grid finds them), each weighted by its pmf.
float MapGuide::voxel_part(const Table &t, const Vec3 &p, const Vec3 &d) const {
    const BBox &b = grid_.bounds();
    float t0, t1;
    if (!chord(b, p, d, t0, t1)) return 0.f;
    const int n = grid_.resolution();
    int ix[3], step[3];
    float next[3], delta[3];
    for (int a = 0; a < 3; ++a) {
        const float q = p[a] + d[a] * t0;
        ix[a] = std::clamp(int((q - b.lo[a]) / cell_size_[a]), 0, n - 1);
        if (d[a] > 0.f) {
            step[a] = 1;
            next[a] = (b.lo[a] + float(ix[a] + 1) * cell_size_[a] - p[a]) / d[a];
            delta[a] = cell_size_[a] / d[a];
        } else if (d[a] < 0.f) {
            step[a] = -1;
            next[a] = (b.lo[a] + float(ix[a]) * cell_size_[a] - p[a]) / d[a];
            delta[a] = -cell_size_[a] / d[a];
        } else {
            step[a] = 0;
            next[a] = std::numeric_limits<float>::infinity();
            delta[a] = 0.f;
        }
    }
    double sum = 0;
    for (int guard = 0; guard < 3 * n + 3; ++guard) {
        const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        const uint32_t j = uint32_t(ix[0] + n * (ix[1] + n * ix[2]));
        if (const float pm = t.pmf[j]; pm > 0.f) {
            // The ray's chord through the voxel's target box (inside the voxel, so within this step).
            if (float s0, s1; chord(boxes_[j], p, d, s0, s1)) {
                const double a0 = s0, a1 = s1;
                sum += double(pm) * double(inv_volume_[j]) * (a1 * a1 * a1 - a0 * a0 * a0);
            }
        }
        if (next[a] >= t1) break;
        ix[a] += step[a];
        if (ix[a] < 0 || ix[a] >= n) break;
        next[a] += delta[a];
    }
    return float(sum / 3.0);
}

nlohmann::json MapGuide::statistics() const {
    size_t targets = 0;
    for (const Table &t : tables_) targets += t.cells.size();
    return {{"kind", "map"},
            {"tables", tables_.size()},
            {"targets_mean", tables_.empty() ? 0.0 : double(targets) / double(tables_.size())},
            {"records", records_}};
}

namespace {

struct Saved {
    int32_t resolution = 0;
    Vec3 lo, hi;
    int32_t scale = 0;
    uint64_t records = 0;
    // voxel -> (samples, target -> (flux, radiance, count))
    struct Totals {
        double flux = 0, radiance = 0;
        uint64_t count = 0;
    };
    std::map<uint32_t, std::pair<uint64_t, std::map<uint32_t, Totals>>> voxels;
    std::map<uint32_t, BBox> seen;  // voxel -> bounds of the end points recorded in it
};

Saved decode(std::string_view bytes) {
    if (bytes.size() < sizeof kMagic || std::memcmp(bytes.data(), kMagic, sizeof kMagic) != 0)
        throw std::runtime_error("guide: not a map guide's state");
    BinaryReader r{bytes, sizeof kMagic, "guide: map guide"};
    Saved s;
    s.resolution = r.get<int32_t>();
    s.lo = r.get<Vec3>();
    s.hi = r.get<Vec3>();
    s.scale = r.get<int32_t>();
    s.records = r.get<uint64_t>();
    if (s.resolution < 1 || s.resolution > VoxelGrid::kMaxResolution) throw std::runtime_error("guide: bad map guide grid");
    const uint64_t voxels = uint64_t(s.resolution) * s.resolution * s.resolution;
    const uint64_t cells = voxels + VoxelGrid::kDirectionBins;
    const uint32_t used = r.get<uint32_t>();
    if (used > voxels) throw std::runtime_error("guide: bad map guide size");
    for (uint32_t u = 0; u < used; ++u) {
        const uint32_t i = r.get<uint32_t>();
        if (i >= voxels || s.voxels.count(i)) throw std::runtime_error("guide: bad map guide voxel");
        auto &[samples, targets] = s.voxels[i];
        samples = r.get<uint64_t>();
        const uint32_t n = r.get<uint32_t>();
        if (n > cells) throw std::runtime_error("guide: bad map guide size");
        for (uint32_t k = 0; k < n; ++k) {
            const uint32_t target = r.get<uint32_t>();
            if (target >= cells || targets.count(target)) throw std::runtime_error("guide: bad map guide target");
            Saved::Totals &t = targets[target];
            t.flux = r.get<double>();
            t.radiance = r.get<double>();
            t.count = r.get<uint64_t>();
            if (!(t.flux >= 0) || !(t.radiance >= 0) || !std::isfinite(t.flux) || !std::isfinite(t.radiance))
                throw std::runtime_error("guide: bad map guide totals");
        }
    }
    const uint32_t bounded = r.get<uint32_t>();
    if (bounded > voxels) throw std::runtime_error("guide: bad map guide size");
    for (uint32_t u = 0; u < bounded; ++u) {
        const uint32_t j = r.get<uint32_t>();
        BBox b;
        b.lo = r.get<Vec3>();
        b.hi = r.get<Vec3>();
        if (j >= voxels || s.seen.count(j) || !b.valid() || !is_finite(b.lo) || !is_finite(b.hi))
            throw std::runtime_error("guide: bad map guide bounds");
        s.seen[j] = b;
    }
    if (r.pos != bytes.size()) throw std::runtime_error("guide: trailing bytes after the map guide");
    return s;
}

bool same_grid(const Saved &a, const Saved &b) { return a.resolution == b.resolution && a.lo == b.lo && a.hi == b.hi; }

std::string encode(const Saved &s) {
    BinaryWriter w{std::string(kMagic, sizeof kMagic)};
    w.put(s.resolution);
    w.put(s.lo);
    w.put(s.hi);
    w.put(s.scale);
    w.put(s.records);
    w.put(uint32_t(s.voxels.size()));
    for (const auto &[i, v] : s.voxels) {
        w.put(i);
        w.put(v.first);
        w.put(uint32_t(v.second.size()));
        for (const auto &[target, t] : v.second) {
            w.put(target);
            w.put(t.flux);
            w.put(t.radiance);
            w.put(t.count);
        }
    }
    w.put(uint32_t(s.seen.size()));
    for (const auto &[j, b] : s.seen) {
        w.put(j);
        w.put(b.lo);
        w.put(b.hi);
    }
    return std::move(w.bytes);
}

}  // namespace

// In ascending (voxel, target) order (Saved's maps), so that equal guides save equal bytes.
std::string MapGuide::save() const {
    Saved s;
    s.resolution = grid_.resolution();
    s.lo = grid_.bounds().lo;
    s.hi = grid_.bounds().hi;
    s.scale = scale_exponent_;
    s.records = records_;
    for (uint32_t i = 0; i < voxels_.size(); ++i) {
        const Voxel &v = voxels_[i];
        if (v.samples == 0) continue;
        auto &[samples, targets] = s.voxels[i];
        samples = v.samples;
        for (const auto &[target, t] : v.total) targets[target] = {t.flux, t.radiance, t.count};
    }
    for (uint32_t j = 0; j < seen_.size(); ++j)
        if (seen_[j].valid()) s.seen[j] = seen_[j];
    return encode(s);
}

void MapGuide::load(std::string_view bytes) {
    const Saved s = decode(bytes);
    Saved mine;
    mine.resolution = grid_.resolution();
    mine.lo = grid_.bounds().lo;
    mine.hi = grid_.bounds().hi;
    if (!same_grid(s, mine)) throw std::runtime_error("guide: the map guide covers another grid");
    for (Voxel &v : voxels_) v = Voxel{};
    for (const auto &[i, saved] : s.voxels) {
        Voxel &v = voxels_[i];
        v.samples = saved.first;
        for (const auto &[target, t] : saved.second) v.total[target] = {t.flux, t.radiance, t.count};
    }
    for (BBox &b : seen_) b = BBox{};
    for (const auto &[j, b] : s.seen) seen_[j] = b;
    set_boxes();
    scale_exponent_ = std::clamp(int(s.scale), -60, 60);
    records_ = s.records;
}

std::string MapGuide::merge(std::string_view base, std::span<const std::string> learned) {
    if (learned.empty()) return std::string(base);
    Saved b = base.empty() ? Saved{} : decode(base);
    Saved out = decode(learned.front());
    const bool have_base = !base.empty();
    if (have_base && !same_grid(b, out)) throw std::runtime_error("guide: map guides of different grids");
    // out = base + Σ (learned - base), summed as Σ learned - (n - 1) base.
    for (size_t l = 1; l < learned.size(); ++l) {
        const Saved s = decode(learned[l]);
        if (!same_grid(s, out)) throw std::runtime_error("guide: map guides of different grids");
        out.records += s.records;
        for (const auto &[j, bounds] : s.seen) out.seen[j].expand(bounds);  // a union: the base's are in each
        for (const auto &[i, v] : s.voxels) {
            auto &o = out.voxels[i];
            o.first += v.first;
            for (const auto &[target, t] : v.second) {
                Saved::Totals &ot = o.second[target];
                ot.flux += t.flux;
                ot.radiance += t.radiance;
                ot.count += t.count;
            }
        }
    }
    if (have_base) {
        const double m = double(learned.size() - 1);
        out.records -= std::min(out.records, b.records * (learned.size() - 1));
        for (const auto &[i, v] : b.voxels) {
            auto &o = out.voxels[i];
            o.first -= std::min(o.first, v.first * (learned.size() - 1));
            for (const auto &[target, t] : v.second) {
                Saved::Totals &ot = o.second[target];
                ot.flux = std::max(0.0, ot.flux - m * t.flux);
                ot.radiance = std::max(0.0, ot.radiance - m * t.radiance);
                ot.count -= std::min(ot.count, t.count * (learned.size() - 1));
            }
        }
    }
    return encode(out);
}

}  // namespace neepp
