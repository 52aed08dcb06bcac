#include "dist/rank_loop.h"

#include <cstdio>

#include "lacuna/error.h"
#include "session/session_file.h"

namespace lacuna::dist {

namespace {

enum class Word : uint8_t { Frame = 1, Refine = 2, Stop = 3, Start = 4 };

constexpr const char* kWhere = "rank 0's frame";

std::vector<uint8_t> frame_word(const TransferFunction& tf, const FrameSpec& spec) {
    SessionFile s;
    s.volume.path = "-";  // the ranks have their bricks already
    s.tf = tf;
    s.frame = spec;
    const std::string text = to_json(s, kWhere);
    std::vector<uint8_t> w(1 + text.size());
    w[0] = uint8_t(Word::Frame);
    std::copy(text.begin(), text.end(), w.begin() + 1);
    return w;
}

// A rank's own failure while rendering: the others may wait for its pixels, so the job ends.
[[noreturn]] void end_job(Comm& comm, const RankFailure& e) {
    std::fprintf(stderr, "lacuna: %s\n", e.what());
    comm.abort(2);
}

}  // namespace

static void tell_all(Comm& comm, const std::vector<uint8_t>& word) {
    for (int r = 1; r < comm.size(); ++r) comm.post(r, word);
}

void announce_start(Comm& comm, const TransferFunction& tf) {
    const std::string text = to_json(tf);
    std::vector<uint8_t> w(1 + text.size());
    w[0] = uint8_t(Word::Start);
    std::copy(text.begin(), text.end(), w.begin() + 1);
    tell_all(comm, w);
}

void announce_failure(Comm& comm) {
    tell_all(comm, {uint8_t(Word::Stop)});
}

std::optional<TransferFunction> await_start(Comm& comm) {
    for (;;) {
        const std::vector<uint8_t> w = comm.await(0);
        if (w.empty()) continue;
        if (Word(w[0]) == Word::Stop) return std::nullopt;
        if (Word(w[0]) == Word::Start)
            return parse_transfer_function(std::string(w.begin() + 1, w.end()), kWhere);
    }
}

void RankDriver::tell(const std::vector<uint8_t>& word) {
    tell_all(m_session.comm(), word);
}

DistFrame RankDriver::frame(const TransferFunction& tf, const FrameSpec& spec) {
    if (m_stopped) throw Error("mpirun", "frame", "the ranks were released");
    tell(frame_word(tf, spec));
    try {
        return m_session.render(tf, spec);
    } catch (const RankFailure& e) {
        end_job(m_session.comm(), e);
    }
}

void RankDriver::refine() {
    if (m_stopped) return;
    tell({uint8_t(Word::Refine)});
    m_session.refine();
}

void RankDriver::stop() {
    if (m_stopped) return;
    m_stopped = true;
    tell({uint8_t(Word::Stop)});
}

void follow_rank0(DistributedSession& session) {
    Comm& comm = session.comm();
    for (;;) {
        const std::vector<uint8_t> word = comm.await(0);
        if (word.empty()) continue;
        try {
            switch (Word(word[0])) {
                case Word::Stop:
                    return;
                case Word::Refine:
                    session.refine();
                    break;
                case Word::Frame: {
                    const SessionFile s =
                        parse_session_file(std::string(word.begin() + 1, word.end()), kWhere);
                    session.render(s.tf, s.frame);
                    break;
                }
                default:
                    break;  // not a word of this build's rank 0: nothing to follow
            }
        } catch (const RankFailure& e) {
            end_job(comm, e);
        } catch (const Error&) {
            // Every rank refused the frame alike; rank 0's page has the message.
        }
    }
}

}  // namespace lacuna::dist
