#include "rl/training_log.h"

#include <algorithm>
#include <cstdlib>
#include <sstream>
#include <vector>

#include "common/error.h"
#include "common/file_io.h"

namespace m2d {
namespace {

constexpr char kHeader[] =
    "iteration,samples,wall_time_s,samples_per_s,mean_return,mean_episode_"
    "length,succ,e2d_px,"
    "policy_loss,value_loss,entropy,learning_rate,approx_kl,clip_fraction,"
    "torch_threads,bf16";

std::vector<std::string> SplitFields(const std::string& row) {
  std::vector<std::string> fields;
  std::istringstream in(row);
  std::string field;
  while (std::getline(in, field, ',')) fields.push_back(field);
  if (!row.empty() && row.back() == ',') fields.emplace_back();
  return fields;
}

}  // namespace

void TrainingLog::Start(const std::string& path) {
  WriteFileAtomic(path, std::string(kHeader) + "\n");
}

LastLogRow TrainingLog::TrimTo(const std::string& path, int iteration) {
  std::ifstream in(path);
  std::ostringstream kept;
  kept << kHeader << "\n";
  const std::vector<std::string> columns = SplitFields(kHeader);
  auto column = [&](const char* name) {
    return static_cast<size_t>(std::find(columns.begin(), columns.end(), name) -
                               columns.begin());
  };
  const size_t wall_time_column = column("wall_time_s");
  const size_t learning_rate_column = column("learning_rate");
  std::string line;
  LastLogRow last;
  std::getline(in, line);  // header
  while (std::getline(in, line)) {
    // Rows past the checkpoint, or torn by a kill mid-write, are dropped. A
    // torn row's iteration is past the checkpoint too, unless the tear cut
    // the number itself short ("1" of "12,..."): hence the comma.
    const int row_iteration = std::atoi(line.c_str());
    const bool whole_iteration = line.find(',') != std::string::npos;
    if (whole_iteration && row_iteration > 0 && row_iteration <= iteration) {
      const std::vector<std::string> fields = SplitFields(line);
      kept << line;
      for (size_t c = fields.size(); c < columns.size(); ++c) kept << ',';
      kept << "\n";
      if (fields.size() > wall_time_column)
        last.wall_time_s = std::atof(fields[wall_time_column].c_str());
      if (fields.size() > learning_rate_column)
        last.learning_rate = std::atof(fields[learning_rate_column].c_str());
    }
  }
  WriteFileAtomic(path, kept.str());
  return last;
}

TrainingLog::TrainingLog(const std::string& path)
    : path_(path), out_(path, std::ios::app) {
  if (!out_) throw InputError(path_, "cannot open the training log");
}

void TrainingLog::Append(const TrainProgress& p) {
  out_ << p.iteration << ',' << p.samples << ',' << p.wall_time_s << ','
       << p.samples_per_s << ',' << p.mean_return << ','
       << p.mean_episode_length << ',' << p.succ << ',' << p.e2d_px << ','
       << p.policy_loss << ',' << p.value_loss << ',' << p.entropy << ','
       << p.learning_rate << ',' << p.approx_kl << ',' << p.clip_fraction << ','
       << p.torch_threads << ',' << (p.bf16 ? 1 : 0) << '\n';
  out_.flush();
  if (!out_) {
    throw InputError(path_,
                     "cannot append to the training log (disk full?); the "
                     "last checkpoint is intact, resume with --resume");
  }
}

}  // namespace m2d
