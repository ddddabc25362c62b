#include "neepp/sampling/primary_sample_space.h"

#include <cmath>
#include <stdexcept>

namespace neepp {

PrimarySampleSpaceSampler::PrimarySampleSpaceSampler(float sigma, float large_step_probability)
    : sigma_(sigma), large_step_probability_(large_step_probability) {}

void PrimarySampleSpaceSampler::restart(uint64_t seed, uint64_t stream) {
    reseed(seed, stream);
    large_key_ = key_;
    x_.clear();
    iteration_ = last_large_step_ = 0;
    proposals_ = 0;
    proposing_ = large_step_ = false;
}

void PrimarySampleSpaceSampler::reseed(uint64_t seed, uint64_t stream) {
    rng_.seed(mix_bits(seed), mix_bits(stream));
    key_ = mix_bits(mix_bits(seed) ^ mix_bits(stream + 0x9e3779b97f4a7c15ULL));
}

bool PrimarySampleSpaceSampler::propose() {
    if (proposing_) throw std::logic_error("PrimarySampleSpaceSampler: a proposal is pending");
    large_step_ = rng_.next_float() < large_step_probability_;
    proposal_key_ = mix_bits(key_ ^ mix_bits(++proposals_));
    ++iteration_;
    proposing_ = true;
    return large_step_;
}

void PrimarySampleSpaceSampler::accept() {
    if (large_step_) last_large_step_ = iteration_, large_key_ = proposal_key_;
    proposing_ = false;
}

void PrimarySampleSpaceSampler::reject() {
    for (Entry &e : x_)
        if (e.modified == iteration_) e.value = e.backup, e.modified = e.backup_modified;
    --iteration_;
    proposing_ = false;
}

void PrimarySampleSpaceSampler::start_evaluation() {
    dims_.fill(0);
    stream_ = SampleStream::Camera;
}

void PrimarySampleSpaceSampler::start_sample(uint32_t, uint32_t, uint32_t) {
    throw std::logic_error("PrimarySampleSpaceSampler is driven by PSSMLT's chains, not per pixel");
}

SampleStream PrimarySampleSpaceSampler::use_stream(SampleStream stream) {
    const SampleStream previous = stream_;
    stream_ = stream;
    return previous;
}

float PrimarySampleSpaceSampler::next(uint32_t index) {
    if (index >= x_.size()) x_.resize(size_t(index) + 1);
    Entry &e = x_[index];
    // Stale past the last accepted large step (or never drawn): the value that step gave it.
    if (e.modified < last_large_step_) {
        e.value = fresh(large_key_, index);
        e.modified = last_large_step_;
    }
    if (proposing_ && e.modified < iteration_) {
        e.backup = e.value, e.backup_modified = e.modified;
        if (large_step_) {
            e.value = fresh(proposal_key_, index);
            e.modified = iteration_;
            return e.value;
        }
    }
    // The small steps it has not received: the accepted ones since it was last brought up to date, and
    // the proposal's own.
    if (const int64_t steps = iteration_ - e.modified; steps > 0) {
        const double u1 = 1.0 - double(rng_.next_float()), u2 = double(rng_.next_float());
        const double normal = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
        double v = double(e.value) + normal * double(sigma_) * std::sqrt(double(steps));
        v -= std::floor(v);
        e.value = v < 1.0 ? float(v) : 0.f;
        if (e.value >= 1.f) e.value = 0.f;  // v just below 1 rounds up in float
        e.modified = iteration_;
    }
    return e.value;
}

float PrimarySampleSpaceSampler::next_1d() {
    const int s = int(stream_);
    return next(dims_[s]++ * kSampleStreams + uint32_t(s));
}

Vec2 PrimarySampleSpaceSampler::next_2d() {
    const float a = next_1d();
    return {a, next_1d()};
}

void PrimarySampleSpaceSampler::save(BinaryWriter &out) const {
    if (proposing_) throw std::logic_error("PrimarySampleSpaceSampler: cannot save while a proposal is pending");
    out.put_vector(x_);
    out.put(iteration_), out.put(last_large_step_);
    out.put(key_), out.put(proposals_), out.put(large_key_);
    out.put(rng_.state()), out.put(rng_.increment());
}

void PrimarySampleSpaceSampler::load(BinaryReader &in) {
    x_ = in.get_vector<Entry>();
    iteration_ = in.get<int64_t>(), last_large_step_ = in.get<int64_t>();
    key_ = in.get<uint64_t>(), proposals_ = in.get<uint64_t>(), large_key_ = in.get<uint64_t>();
    const uint64_t state = in.get<uint64_t>(), inc = in.get<uint64_t>();
    rng_.set_state(state, inc);
    proposing_ = large_step_ = false;
}

std::unique_ptr<Sampler> PrimarySampleSpaceSampler::clone() const {
    return std::make_unique<PrimarySampleSpaceSampler>(*this);
}

}  // namespace neepp
