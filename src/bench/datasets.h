// The benchmark datasets of `lacuna bench faludi`: a volume plus a transfer function each (the
// rows of the paper's Table 1, on our data). A closed set, named once here (STYLE.md habit 3:
// the CLI parses the names, the library sees the enum).
#pragma once
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "lacuna/transfer_function.h"
#include "lacuna/volume.h"

namespace lacuna::bench {

enum class DatasetId {
    Ch2Skin,         // ch2.nii.gz, the whole head, mr-skin
    Ch2betterBrain,  // ch2better.nii.gz (brain, 0.5 mm), mr-brain
    Ch2betterGap,    // ch2better.nii.gz, mr-gap (an opacity gap: the paper's Figure 3 case)
    Ch2betBrain,     // ch2bet.nii.gz (skull-stripped), mr-brain
    Aal,             // aal.nii.gz, the AAL atlas read as a scalar volume, mr-default
    AalLabels,       // aal.nii.gz, label-band (six labels: the case for nearest sampling)
    Inia19,          // inia19-t1-brain.nii.gz (float32), mr-brain
    Tree512,         // generated sparse tree-like volume, 512^3 uint8 (in memory only)
};

std::string to_string(DatasetId d);  // "ch2-skin", "ch2better-brain", ...
// Throws lacuna::Error("--datasets", "dataset", "unknown 'x'; expected one of: ...").
DatasetId parse_dataset(const std::string& name);
std::vector<std::string> dataset_names();
std::vector<DatasetId> all_datasets();

// A ready-to-benchmark dataset. Rows sharing a file share the volume.
struct BenchDataset {
    std::string name;         // row label, e.g. "ch2better-gap"
    std::string description;  // where it came from, e.g. "ch2better.nii.gz (mricron), mr-gap"
    std::shared_ptr<const Volume> volume;
    std::string tf_name;
    TransferFunction tf;  // what a Session renders it with (Session::set_transfer_function)
    TransferLut lut;      // tf discretised over the volume's visualization range
};

struct DatasetSource {
    std::string templates_dir = "/usr/share/mricron/templates";  // Debian package mricron-data
    int tree_size = 512;  // edge of the generated tree volume
    uint32_t tree_seed = 1;
    int threads = 0;  // generation threads (0 = all)
};

// A dataset from a volume already in memory (tests, custom runs).
BenchDataset make_dataset(std::string name, std::string description,
                          std::shared_ptr<const Volume> volume, const TransferFunction& tf);

// Loads the datasets in order (each file read once). `log` (may be null) gets one line per load.
// Throws lacuna::Error when a file is missing or unreadable.
std::vector<BenchDataset> load_datasets(const std::vector<DatasetId>& ids, const DatasetSource& src,
                                        const std::function<void(const std::string&)>& log = {});

}  // namespace lacuna::bench
