// Helpers shared by the transfer-function tests (presets_test.cpp, transfer_json_test.cpp).
#pragma once
#include <gtest/gtest.h>

#include <filesystem>
#include <functional>
#include <string>

#include "lacuna/error.h"

namespace lacuna::test {

// The message of the lacuna::Error that `f` throws (a marker string if it throws none).
inline std::string error_message(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "(no lacuna::Error thrown)";
}

// A path in gtest's temp folder, named after the running test and `file`.
inline std::string temp_path(const std::string& file) {
    const auto* info = testing::UnitTest::GetInstance()->current_test_info();
    return (std::filesystem::path(testing::TempDir()) /
            (std::string("lacuna_") + info->name() + "_" + file))
        .string();
}

}  // namespace lacuna::test
