#include "bench/datasets.h"

#include <chrono>
#include <cstdio>
#include <map>

#include "lacuna/error.h"
#include "lacuna/io.h"
#include "lacuna/synthetic.h"

namespace lacuna::bench {

namespace {

struct Entry {
    DatasetId id;
    const char* name;
    const char* file;  // in the templates folder; nullptr for generated volumes
    const char* tf;
};
constexpr Entry kDatasets[] = {
    {DatasetId::Ch2Skin, "ch2-skin", "ch2.nii.gz", "mr-skin"},
    {DatasetId::Ch2betterBrain, "ch2better-brain", "ch2better.nii.gz", "mr-brain"},
    {DatasetId::Ch2betterGap, "ch2better-gap", "ch2better.nii.gz", "mr-gap"},
    {DatasetId::Ch2betBrain, "ch2bet-brain", "ch2bet.nii.gz", "mr-brain"},
    {DatasetId::Aal, "aal", "aal.nii.gz", "mr-default"},
    {DatasetId::AalLabels, "aal-labels", "aal.nii.gz", "label-band"},
    {DatasetId::Inia19, "inia19", "inia19-t1-brain.nii.gz", "mr-brain"},
    {DatasetId::Tree512, "tree512", nullptr, "mr-default"},
};

const Entry& entry(DatasetId id) {
    for (const auto& e : kDatasets)
        if (e.id == id) return e;
    throw Error("--datasets", "dataset", "unhandled id");
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace

std::string to_string(DatasetId d) {
    return entry(d).name;
}

std::vector<std::string> dataset_names() {
    std::vector<std::string> out;
    for (const auto& e : kDatasets) out.push_back(e.name);
    return out;
}

std::vector<DatasetId> all_datasets() {
    std::vector<DatasetId> out;
    for (const auto& e : kDatasets) out.push_back(e.id);
    return out;
}

DatasetId parse_dataset(const std::string& name) {
    for (const auto& e : kDatasets)
        if (name == e.name) return e.id;
    std::string valid;
    for (const auto& e : kDatasets) valid += (valid.empty() ? "" : ", ") + std::string(e.name);
    throw Error("--datasets", "dataset", "unknown '" + name + "'; expected one of: " + valid);
}

BenchDataset make_dataset(std::string name, std::string description,
                          std::shared_ptr<const Volume> volume, const TransferFunction& tf) {
    BenchDataset d;
    d.name = std::move(name);
    d.description = std::move(description);
    d.tf_name = tf.name;
    d.tf = tf;
    d.lut = discretise(tf, volume->vis_range());
    d.volume = std::move(volume);
    return d;
}

std::vector<BenchDataset> load_datasets(const std::vector<DatasetId>& ids, const DatasetSource& src,
                                        const std::function<void(const std::string&)>& log) {
    std::map<std::string, std::shared_ptr<const Volume>> loaded;  // by file: read each once
    std::vector<BenchDataset> out;
    char line[512];
    for (DatasetId id : ids) {
        const Entry& e = entry(id);
        const TransferFunction tf = preset(e.tf);
        const auto t0 = std::chrono::steady_clock::now();
        std::shared_ptr<const Volume> vol;
        std::string description;
        std::string name = e.name;
        if (e.file) {
            const std::string path = src.templates_dir + "/" + e.file;
            auto it = loaded.find(path);
            if (it == loaded.end())
                it = loaded.emplace(path, std::make_shared<const Volume>(read_volume(path))).first;
            vol = it->second;
            description = std::string(e.file) + " (mricron), " + e.tf;
        } else {
            SyntheticOptions so;
            so.dims = {src.tree_size, src.tree_size, src.tree_size};
            so.type = VoxelType::UInt8;
            so.seed = src.tree_seed;
            so.threads = src.threads;
            vol = std::make_shared<const Volume>(generate(SyntheticKind::Tree, so));
            name = "tree" + std::to_string(src.tree_size);
            description = "generate(tree, " + std::to_string(src.tree_size) + "^3 uint8, seed " +
                          std::to_string(src.tree_seed) + ") in memory, " + e.tf;
        }
        out.push_back(make_dataset(name, description, vol, tf));
        if (log) {
            const Vec3i d = vol->dims();
            std::snprintf(line, sizeof line, "dataset %s: %dx%dx%d %s, %.2f MiB, ready in %.2f s",
                          name.c_str(), d.x, d.y, d.z, lacuna::to_string(vol->type()).c_str(),
                          double(vol->bytes()) / (1 << 20), seconds_since(t0));
            log(line);
        }
    }
    return out;
}

}  // namespace lacuna::bench
