// The viewer's WebSocket messages (src/serve/protocol.h): every message type the server answers,
// parsed as the server parses it (message_kind, then that kind's parser), on arbitrary text with
// the server's default limits. What the server does next with an accepted message is done here
// too, short of rendering: a render or screenshot TF discretised over a volume's range and its
// map evaluated, the "hide" list applied to a label table, an uploaded TF (tf_import) or session
// file (session_import) read by the library's readers, a frame number checked against a 4D file's
// count; and the error answer built for a rejected message (valid JSON for any bytes it echoes).
#include "serve/protocol.h"

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "fuzz_util.h"
#include "lacuna/segments.h"
#include "lacuna/transfer_function.h"
#include "session/session_file.h"

using namespace lacuna;
using fuzz::fuzz_check;

namespace {

void check_view(const serve::ViewRequest& req, const serve::Limits& limits) {
    fuzz_check(req.width >= 1 && req.width <= limits.max_side && req.height >= 1 &&
                   req.height <= limits.max_side,
               "image size within limits",
               std::to_string(req.width) + "x" + std::to_string(req.height));
    const TransferLut lut = discretise(req.tf, ValueRange{-1024.f, 3071.f});
    const ValueToLut map = lut.map();
    for (float v : {lut.vis.min, lut.vis.max, -3e38f, 3e38f, 0.f}) {
        const int e = map(v);
        fuzz_check(e >= 0 && e < lut.size(), "map entry in range", std::to_string(e));
    }
    if (!req.hide.empty()) {
        LabelTable t;
        t.styles.resize(64);
        set_label_visibility(t, req.hide, false, "hide");
    }
}

void answer(const std::string& text, const serve::Limits& limits) {
    using serve::MessageKind;
    switch (serve::message_kind(text, limits)) {
        case MessageKind::Render:
            check_view(serve::parse_request(text, limits), limits);
            return;
        case MessageKind::Screenshot:
        case MessageKind::Session: {
            const MessageKind k = serve::message_kind(text, limits);
            const serve::ViewRequest r = serve::parse_view_request(text, k, limits);
            fuzz_check(!r.preview, "screenshot and session requests are never previews");
            check_view(r, limits);
            return;
        }
        case MessageKind::Slice: {
            const serve::SliceRequest r = serve::parse_slice_request(text, limits);
            fuzz_check(r.window > 0 && r.overlay_opacity >= 0 && r.overlay_opacity <= 1 &&
                           r.max_size >= 0 && r.max_size <= limits.max_side,
                       "slice request within its ranges");
            return;
        }
        case MessageKind::Probe:
            (void)serve::parse_probe_request(text, limits);
            return;
        case MessageKind::TfExport: {
            const serve::TfExportRequest r = serve::parse_tf_export_request(text, limits);
            (void)discretise(r.tf, ValueRange{0.f, 255.f});
            return;
        }
        case MessageKind::TfImport: {
            const serve::TfImportRequest r = serve::parse_tf_import_request(text, limits);
            (void)parse_transfer_function(r.text, r.name);  // the lacuna JSON reader
            return;
        }
        case MessageKind::SessionImport: {
            const serve::TfImportRequest r = serve::parse_session_import_request(text, limits);
            (void)parse_session_file(r.text, r.name.empty() ? "session" : r.name);
            return;
        }
        case MessageKind::VolumeFrame: {
            const serve::VolumeFrameRequest r = serve::parse_volume_frame_request(text, limits);
            fuzz_check(r.frame >= 0, "frame is not negative", std::to_string(r.frame));
            return;
        }
    }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    const serve::Limits limits;
    (void)serve::request_id(text, limits);
    try {
        answer(text, limits);
    } catch (const Error& e) {
        const std::string reply = serve::error_message(e.what(), serve::request_id(text, limits));
        fuzz_check(nlohmann::json::accept(reply), "error answer is JSON", reply);
    }
    return 0;
}
