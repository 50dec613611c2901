#pragma once
/// @file
/// The binary trajectory (`--format hdf5`, `[output] format = "hdf5"`): trajectory.h5, an HDF5 file with one 2-D
/// float64 dataset per table (rows x columns, row-major, as the run holds it) whose attribute `columns` names the
/// columns (UTF-8 strings). Read with h5py: `f["trajectory"][:]`, `f["trajectory"].attrs["columns"]`.
/// (Private: run_output.cpp's.)

#include <cstddef>
#include <string>
#include <vector>

#include "redres/common/output_file.hpp"
#include "redres/run/trajectory.hpp"

namespace redres {

/// One table of the file: its dataset name, the table, and every `every`-th row kept (and the last).
struct Hdf5Table {
  std::string name;
  const Trajectory* table = nullptr;
  std::size_t every = 1;
};

/// Writes an HDF5 file that holds `tables` into `file` (a StagedFile, created exclusively and not yet written):
/// HDF5 opens the very file the StagedFile created, through /proc/self/fd, so it is written in place, with no copy
/// in memory, and installed as every output is. Serialised process-wide (Debian's HDF5 is not thread-safe).
/// std::runtime_error naming HDF5's call on failure; then finish() on the StagedFile is not called (the caller's
/// StagedFile removes its temporary).
void write_hdf5(const std::vector<Hdf5Table>& tables, StagedFile& file);

}  // namespace redres
