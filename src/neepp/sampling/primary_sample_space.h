// Kelemen et al. 2002's primary sample space: a sample of the image is a function of a vector of uniform
// numbers, and primary-sample-space MLT explores the image by mutating that vector. This sampler hands
// out the vector's entries, one sequence per SampleStream (interleaved in one array), and proposes its
// mutations: a large step draws every entry afresh, a small step moves each by a normal offset of
// standard deviation sigma, wrapped around [0, 1). Entries are brought up to date only when read (the
// vector is as long as the longest path needs): an entry left unread over n accepted small steps gets
// them at once, as one offset of standard deviation sigma·sqrt(n), and one left unread since before the
// last accepted large step gets the value that step gave it.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>
#include "neepp/io/binary_io.h"
#include "neepp/sampling/rng.h"
#include "neepp/sampling/sampler.h"

namespace neepp {

class PrimarySampleSpaceSampler final : public Sampler {
public:
    PrimarySampleSpaceSampler(float sigma, float large_step_probability);

    // Forgets every entry and draws the next ones from a generator seeded with (seed, stream): the next
    // evaluation reads fresh uniform numbers, and the same seed gives the same ones again.
    void restart(uint64_t seed, uint64_t stream);
    // Keeps the entries and draws what follows (entries not read yet, mutations) from a new generator.
    void reseed(uint64_t seed, uint64_t stream);
    // Proposes a mutation of the current state, to be read by the next evaluation and then accepted or
    // rejected; returns whether it is a large step.
    bool propose();
    void accept();
    void reject();
    // Rewinds every stream to its first entry: call before each evaluation, of a proposal or (without
    // propose) of the current state again.
    void start_evaluation();
    // A uniform number for the chain's own decisions (large step or not, acceptance), apart from the entries.
    float uniform() { return rng_.next_float(); }

    void start_sample(uint32_t, uint32_t, uint32_t) override;  // unused: PSSMLT drives the sampler
    float next_1d() override;
    Vec2 next_2d() override;
    SampleStream use_stream(SampleStream stream) override;
    std::unique_ptr<Sampler> clone() const override;
    std::string name() const override { return "primary_sample_space"; }

    // The chain's whole state (entries, iteration, generator), for checkpoints; between proposals only.
    void save(BinaryWriter &out) const;
    void load(BinaryReader &in);

    uint64_t iteration() const { return iteration_; }
    size_t entries() const { return x_.size(); }

private:
    struct Entry {
        float value = 0, backup = 0;
        int64_t modified = -1, backup_modified = -1;  // the iteration whose value it holds (-1: none yet)
    };
    float next(uint32_t index);
    // An entry's value after the large step keyed `key`: a hash, so that a state's fresh numbers do not
    // depend on the order its entries are read in (each stream's are the same however many the others read).
    static float fresh(uint64_t key, uint32_t index) {
        return float(mix_bits(key ^ mix_bits(uint64_t(index) + 1)) >> 40) * 0x1p-24f;
    }

    float sigma_, large_step_probability_;
    PCG32 rng_;  // small steps' offsets and the chain's decisions
    uint64_t key_ = 0, proposals_ = 0;
    uint64_t large_key_ = 0, proposal_key_ = 0;  // of the last accepted large step, of the pending proposal
    std::vector<Entry> x_;
    int64_t iteration_ = 0;          // the current state's (proposals are iteration_ while pending)
    int64_t last_large_step_ = 0;    // the iteration of the last accepted large step (0: the first state)
    bool proposing_ = false, large_step_ = false;
    SampleStream stream_ = SampleStream::Camera;
    std::array<uint32_t, kSampleStreams> dims_{};  // entries read per stream in this evaluation
};

}  // namespace neepp
