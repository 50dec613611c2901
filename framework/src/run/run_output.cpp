#include "redres/run/run_output.hpp"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include <unistd.h>

#include "common/input_file.hpp"
#include "redres/common/error.hpp"
#include "redres/common/output_file.hpp"
#include "redres/model/kinematics.hpp"
#include "run/hdf5_output.hpp"

namespace redres {

namespace {

// A table as comma-separated text with one header line. Numbers are written by std::to_chars in their shortest
// round-trip form (reading the text back gives the same doubles, bit for bit), into a buffer written in large
// blocks: several times faster than printf("%.17g").
void write_csv(const Trajectory& table, StagedFile& file, std::size_t every = 1) {
  constexpr std::size_t kBlock = 1 << 16;
  std::string out;
  out.reserve(kBlock + 4096);
  const auto& cols = table.columns();
  for (std::size_t c = 0; c < cols.size(); ++c) (out += c ? "," : "") += cols[c];
  out += '\n';
  char number[64];
  for (std::size_t r = 0; r < table.size(); ++r) {
    if (!recorded_row(r, table.size(), every)) continue;
    const double* row = table.row(r);
    for (std::size_t c = 0; c < table.width(); ++c) {
      if (c != 0) out += ',';
      const auto end = std::to_chars(number, number + sizeof(number), row[c]).ptr;
      out.append(number, end);
    }
    out += '\n';
    if (out.size() >= kBlock) {
      file.write(out);
      out.clear();
    }
  }
  file.write(out);
  file.finish();
}

// Columns per joint in frames.csv: origin, then the rotation row by row.
constexpr std::size_t kFrameColumns = 12;

}  // namespace

Trajectory joint_frames(const RobotModel& robot, const Trajectory& run, std::size_t max_rows) {
  REDRES_REQUIRE(max_rows >= 2, "joint_frames", "max_rows >= 2");
  const int n = robot.dof();
  const auto joints = static_cast<std::size_t>(n);
  std::vector<std::string> columns = {"t"};
  std::vector<std::size_t> c_theta;
  for (int j = 1; j <= n; ++j) {
    const std::string J = std::to_string(j);
    for (const char* c : {"_x", "_y", "_z", "_r11", "_r12", "_r13", "_r21", "_r22", "_r23", "_r31", "_r32", "_r33"}) {
      columns.push_back("joint_" + J + c);
    }
    c_theta.push_back(run.column("theta_" + J));
  }
  for (const char* axis : {"ee_x", "ee_y", "ee_z"}) columns.emplace_back(axis);
  const std::size_t rows = run.size();
  // Stride k = ceil((rows - 1) / (max_rows - 1)) keeps floor((rows - 1) / k) + 1 <= max_rows rows, plus the last
  // one when the stride does not land on it, which then had room (floor((rows - 1) / k) <= max_rows - 2).
  const std::size_t stride = rows <= max_rows ? 1 : (rows - 1 + max_rows - 2) / (max_rows - 1);
  std::vector<std::size_t> kept;
  for (std::size_t r = 0; r < rows; r += stride) kept.push_back(r);
  if (rows > 0 && kept.back() != rows - 1) kept.push_back(rows - 1);
  Trajectory out(std::move(columns), kept.size());
  const std::size_t c_t = run.column("t");
  KinematicsData k(robot);
  Eigen::VectorXd theta(n);
  const auto put = [](double* at, const Eigen::Vector3d& p) {
    at[0] = p.x();
    at[1] = p.y();
    at[2] = p.z();
  };
  for (const std::size_t r : kept) {
    for (std::size_t j = 0; j < joints; ++j) theta(static_cast<Eigen::Index>(j)) = run(r, c_theta[j]);
    compute_kinematics(robot, theta, k, KinematicsLevel::kPosition);
    double* row = out.append_row();
    row[0] = run(r, c_t);
    for (std::size_t j = 0; j < joints; ++j) {
      const Eigen::Isometry3d& T = k.link_frames[j];
      double* at = row + 1 + kFrameColumns * j;
      put(at, T.translation());
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) at[3 + 3 * a + b] = T.linear()(a, b);
      }
    }
    put(row + 1 + kFrameColumns * joints, k.ee_pose.translation());
  }
  return out;
}

namespace {

bool manifest_name_ok(const std::string& name) {
  return !name.empty() && name.find('/') == std::string::npos && name.find('\t') == std::string::npos && name[0] != '.';
}

constexpr const char* kManifestHeader =
    "# redres outputs: the files the last run wrote into this directory, each with its size, modification time (ns) "
    "and inode when written; the next run removes those it does not write again, and only while they are unchanged";

struct ManifestEntry {
  std::string name;
  FileStamp stamp;  // exists == false: named without a stamp (hand-written, or an old manifest): never removed
};

std::vector<ManifestEntry> read_manifest(const std::filesystem::path& dir) {
  std::vector<ManifestEntry> entries;
  const std::filesystem::path file = dir / kOutputManifest;
  if (!stamp_of(file).exists) return entries;  // missing, or not a regular file (a link is never followed)
  // A manifest is trusted only when this user wrote it and no one else can change it: in a directory others may
  // write to (a sticky /tmp, say), another user could plant one naming this user's files with their stamps.
  if (!owned_by_me_alone(file)) return entries;
  std::string text;
  try {
    text = read_input_file(file, "output manifest", std::uintmax_t{1} << 20);
  } catch (const std::exception&) {
    return entries;  // unreadable: nothing is recognised, so nothing is removed
  }
  std::size_t at = 0;
  while (at < text.size()) {
    std::size_t end = text.find('\n', at);
    if (end == std::string::npos) end = text.size();
    const std::string line = text.substr(at, end - at);
    at = end + 1;
    if (line.empty() || line[0] == '#') continue;
    ManifestEntry e;
    const std::size_t tab = line.find('\t');
    e.name = line.substr(0, tab);
    if (!manifest_name_ok(e.name)) continue;
    if (tab != std::string::npos) {
      unsigned long long size = 0, inode = 0;
      long long mtime = 0;
      char extra = 0;
      if (std::sscanf(line.c_str() + tab + 1, "%llu\t%lld\t%llu%c", &size, &mtime, &inode, &extra) == 3) {
        e.stamp = {true, size, mtime, inode};
      }
    }
    entries.push_back(std::move(e));
  }
  return entries;
}

void write_manifest(const std::filesystem::path& dir, const std::vector<ManifestEntry>& entries) {
  std::string text = std::string(kManifestHeader) + "\n";
  for (const auto& e : entries) {
    text += e.name;
    if (e.stamp.exists) {
      text += "\t" + std::to_string(e.stamp.size) + "\t" + std::to_string(e.stamp.mtime_ns) + "\t" +
              std::to_string(e.stamp.inode);
    }
    text += "\n";
  }
  write_text_file(dir / kOutputManifest, text);
}

// The entries for files just written into DIR: stamped as they are now.
std::vector<ManifestEntry> stamped(const std::filesystem::path& dir, const std::vector<std::string>& names) {
  std::vector<ManifestEntry> entries;
  for (const auto& n : names) {
    if (!manifest_name_ok(n)) continue;
    const FileStamp s = stamp_of(dir / n);
    if (s.exists) entries.push_back({n, s});
  }
  return entries;
}

}  // namespace

std::vector<std::string> read_output_manifest(const std::filesystem::path& dir) {
  std::vector<std::string> names;
  for (auto& e : read_manifest(dir)) names.push_back(std::move(e.name));
  return names;
}

void add_to_output_manifest(const std::filesystem::path& dir, const std::vector<std::string>& names) {
  std::vector<ManifestEntry> all = read_manifest(dir);
  for (auto& e : stamped(dir, names)) {
    const auto same = std::find_if(all.begin(), all.end(), [&e](const ManifestEntry& a) { return a.name == e.name; });
    if (same == all.end()) {
      all.push_back(std::move(e));
    } else {
      *same = std::move(e);
    }
  }
  write_manifest(dir, all);
}

bool remove_earlier_output(const std::filesystem::path& dir, const std::string& name) {
  for (const auto& e : read_manifest(dir)) {
    if (e.name == name) return remove_if_unchanged(dir / name, e.stamp);
  }
  return false;
}

void prepare_output_dir(const std::filesystem::path& dir, const std::string& what) {
  const std::string where = what + " " + dir.string() + ": ";
  std::error_code ec;
  const auto status = std::filesystem::status(dir, ec);
  if (std::filesystem::exists(status) && !std::filesystem::is_directory(status)) {
    throw std::runtime_error(where + "exists and is not a directory");
  }
  if (!std::filesystem::exists(status)) {
    std::filesystem::create_directories(dir, ec);
    if (ec) throw std::runtime_error(where + "cannot create the directory: " + ec.message());
  }
  try {
    StagedFile probe(dir / "probe");  // created exclusively and removed again: never installed
    probe.write("probe\n");
    probe.finish();
  } catch (const std::exception& e) {
    throw std::runtime_error(where + "cannot write into the directory (" + e.what() + ")");
  }
  for (const char* name : {"trajectory.csv", "frames.csv", "trajectory.h5", "summary.json", kOutputManifest}) {
    require_replaceable(dir / name, what + ": redres cannot write");
  }
}

std::vector<std::string> write_run(const RobotModel& robot, const RunResult& run, const RunSummary& summary,
                                   const std::filesystem::path& dir, const RecordOptions& record) {
  REDRES_REQUIRE(record.every >= 1, "write_run", "record.every >= 1");
  std::filesystem::create_directories(dir);
  // Every file is written to a temporary beside it first, so that a failed write (a full disk, a read-only
  // directory) leaves the directory as it was. Then the old summary goes, the tables are renamed into place, and
  // the summary comes last: a reader that finds summary.json finds the complete tables of the same run.
  const std::filesystem::path summary_file = dir / "summary.json";
  std::vector<StagedFile> staged;  // installed in this order, summary.json last
  if (!record.none && record.format == TrajectoryFormat::kHdf5) {
    const Trajectory frames = joint_frames(robot, run.trajectory);
    write_hdf5({{"trajectory", &run.trajectory, record.every}, {"frames", &frames, 1}},
               staged.emplace_back(dir / "trajectory.h5"));
  } else if (!record.none) {
    write_csv(run.trajectory, staged.emplace_back(dir / "trajectory.csv"), record.every);
    write_csv(joint_frames(robot, run.trajectory), staged.emplace_back(dir / "frames.csv"));
  }
  StagedFile& js = staged.emplace_back(summary_file);
  js.write(to_json(summary));
  js.write("\n");
  js.finish();
  std::vector<std::string> written;
  for (const auto& f : staged) written.push_back(f.final_name().filename().string());
  // What an earlier run wrote and this one does not is stale: removed, before this run's files appear, when it is
  // still the file that run wrote (same size, time and inode; never a link). A file the manifest does not stamp
  // (a hand-written or planted manifest, a file edited or replaced since) stays.
  for (const auto& e : read_manifest(dir)) {
    if (std::find(written.begin(), written.end(), e.name) != written.end()) continue;
    (void)remove_if_unchanged(dir / e.name, e.stamp);
  }
  for (auto& f : staged) f.install();
  write_manifest(dir, stamped(dir, written));
  return written;
}

}  // namespace redres
