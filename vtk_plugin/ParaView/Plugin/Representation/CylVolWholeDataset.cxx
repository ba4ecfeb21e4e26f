// The whole dataset's structure, axis and default step, from a sample of its cells that does
// not depend on how the dataset is split among the ranks (see CylVolWholeDataset.h).
#include "CylVolWholeDataset.h"

#include "vtkCellType.h"
#include "vtkMultiProcessController.h"
#include "vtkPoints.h"
#include "vtkUnstructuredGrid.h"

#include <cylvol.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <numeric>
#include <vector>

namespace cylvolpv
{
namespace
{
// The cell types cylvol takes (as vtkCylVolMapper does).
bool TakenByCylVol(int type)
{
  return type == VTK_HEXAHEDRON || type == VTK_VOXEL || type == VTK_WEDGE ||
    type == VTK_PYRAMID || type == VTK_TETRA;
}

uint64_t Mix(uint64_t x)
{
  // SplitMix64's finaliser: every input bit moves every output bit.
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

uint64_t Bits(double value)
{
  uint64_t bits = 0;
  std::memcpy(&bits, &value, sizeof bits);
  return bits;
}

// A hash of a cell's corners (their mean, bit for bit): the same for the same cell on any rank.
uint64_t CellHash(const double* corners, int count)
{
  double centre[3] = { 0.0, 0.0, 0.0 };
  for (int i = 0; i < count; ++i)
  {
    for (int k = 0; k < 3; ++k)
    {
      centre[k] += corners[3 * i + k];
    }
  }
  uint64_t h = 0;
  for (double c : centre)
  {
    h = Mix(h ^ Bits(c / count));
  }
  return h;
}

// Cells as a flat list: each cell's VTK type and its corners' coordinates, one after another.
struct CellList
{
  std::vector<unsigned char> Types;
  std::vector<double> Corners;
};

int CornerCount(unsigned char type)
{
  switch (type)
  {
    case VTK_TETRA:
      return 4;
    case VTK_PYRAMID:
      return 5;
    case VTK_WEDGE:
      return 6;
    default:
      return 8;
  }
}

double CountTaken(vtkUnstructuredGrid* piece)
{
  if (!piece || !piece->GetCellTypesArray())
  {
    return 0.0;
  }
  double n = 0.0;
  for (vtkIdType c = 0; c < piece->GetNumberOfCells(); ++c)
  {
    n += TakenByCylVol(piece->GetCellType(c)) ? 1.0 : 0.0;
  }
  return n;
}

// The cells of `piece` whose hash lies below `fraction` of the hash range.
CellList LocalSample(vtkUnstructuredGrid* piece, double fraction)
{
  CellList sample;
  if (!piece || !piece->GetPoints() || !piece->GetCellTypesArray())
  {
    return sample;
  }
  const long double limit = static_cast<long double>(fraction) * 18446744073709551616.0L;
  std::vector<double> corners;
  for (vtkIdType c = 0; c < piece->GetNumberOfCells(); ++c)
  {
    const int type = piece->GetCellType(c);
    if (!TakenByCylVol(type))
    {
      continue;
    }
    vtkIdType count = 0;
    const vtkIdType* ids = nullptr;
    piece->GetCellPoints(c, count, ids);
    if (count != CornerCount(static_cast<unsigned char>(type)))
    {
      continue;
    }
    corners.resize(static_cast<size_t>(3 * count));
    for (vtkIdType i = 0; i < count; ++i)
    {
      piece->GetPoints()->GetPoint(ids[i], &corners[static_cast<size_t>(3 * i)]);
    }
    if (fraction < 1.0 &&
      static_cast<long double>(CellHash(corners.data(), static_cast<int>(count))) >= limit)
    {
      continue;
    }
    sample.Types.push_back(static_cast<unsigned char>(type));
    sample.Corners.insert(sample.Corners.end(), corners.begin(), corners.end());
  }
  return sample;
}

// Every rank's sample on rank 0 (the others get an empty list).
CellList GatherOnFirstRank(const CellList& local, vtkMultiProcessController* controller)
{
  const int ranks = controller ? controller->GetNumberOfProcesses() : 1;
  if (ranks <= 1)
  {
    return local;
  }
  const int rank = controller->GetLocalProcessId();
  const double counts[2] = { static_cast<double>(local.Types.size()),
    static_cast<double>(local.Corners.size()) };
  std::vector<double> all(2 * static_cast<size_t>(ranks), 0.0);
  controller->Gather(counts, all.data(), 2, 0);
  std::vector<vtkIdType> typeLengths(ranks), typeOffsets(ranks), cornerLengths(ranks),
    cornerOffsets(ranks);
  vtkIdType types = 0, corners = 0;
  for (int r = 0; r < ranks; ++r)
  {
    typeLengths[r] = static_cast<vtkIdType>(all[2 * r]);
    cornerLengths[r] = static_cast<vtkIdType>(all[2 * r + 1]);
    typeOffsets[r] = types;
    cornerOffsets[r] = corners;
    types += typeLengths[r];
    corners += cornerLengths[r];
  }
  CellList gathered;
  if (rank == 0)
  {
    gathered.Types.resize(static_cast<size_t>(types));
    gathered.Corners.resize(static_cast<size_t>(corners));
  }
  unsigned char noType = 0;
  double noCorner = 0.0;
  controller->GatherV(local.Types.empty() ? &noType : local.Types.data(),
    gathered.Types.empty() ? &noType : gathered.Types.data(),
    static_cast<vtkIdType>(local.Types.size()), typeLengths.data(), typeOffsets.data(), 0);
  controller->GatherV(local.Corners.empty() ? &noCorner : local.Corners.data(),
    gathered.Corners.empty() ? &noCorner : gathered.Corners.data(),
    static_cast<vtkIdType>(local.Corners.size()), cornerLengths.data(), cornerOffsets.data(), 0);
  return gathered;
}

// The sample in the order of its cells' hashes (ties by their corners), whichever ranks sent
// them in whichever order.
CellList Ordered(const CellList& cells)
{
  const size_t n = cells.Types.size();
  std::vector<size_t> start(n);
  std::vector<uint64_t> hash(n);
  size_t at = 0;
  for (size_t i = 0; i < n; ++i)
  {
    const int count = CornerCount(cells.Types[i]);
    start[i] = at;
    hash[i] = CellHash(&cells.Corners[at], count);
    at += static_cast<size_t>(3 * count);
  }
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), size_t{ 0 });
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    if (hash[a] != hash[b])
    {
      return hash[a] < hash[b];
    }
    const int ca = 3 * CornerCount(cells.Types[a]), cb = 3 * CornerCount(cells.Types[b]);
    return std::lexicographical_compare(&cells.Corners[start[a]], &cells.Corners[start[a]] + ca,
      &cells.Corners[start[b]], &cells.Corners[start[b]] + cb);
  });
  CellList ordered;
  ordered.Types.reserve(n);
  ordered.Corners.reserve(cells.Corners.size());
  for (size_t i : order)
  {
    const size_t count = static_cast<size_t>(3 * CornerCount(cells.Types[i]));
    ordered.Types.push_back(cells.Types[i]);
    ordered.Corners.insert(ordered.Corners.end(), &cells.Corners[start[i]],
      &cells.Corners[start[i]] + count);
  }
  return ordered;
}

std::string StatusText(CylvolStatus status)
{
  std::string text = cylvol_status_message(status);
  const char* detail = cylvol_last_error();
  if (detail && *detail)
  {
    text += ": ";
    text += detail;
  }
  return text;
}

// cylvol's build over the sample (each cell with corners of its own): the structure, axis and
// default step it chose.
void BuildOverSample(const CellList& sample, const WholeDatasetRequest& request,
  WholeDatasetChoice& choice)
{
  const size_t cells = sample.Types.size();
  if (cells == 0)
  {
    choice.Problem = "the dataset has no cell cylvol takes";
    return;
  }
  std::vector<int64_t> offsets(cells + 1, 0);
  for (size_t i = 0; i < cells; ++i)
  {
    offsets[i + 1] = offsets[i] + CornerCount(sample.Types[i]);
  }
  std::vector<int64_t> connectivity(static_cast<size_t>(offsets[cells]));
  std::iota(connectivity.begin(), connectivity.end(), int64_t{ 0 });
  CylvolMesh* mesh = nullptr;
  CylvolStatus status = cylvol_mesh_new(sample.Corners.data(), CYLVOL_VALUE_F64,
    sample.Corners.size() / 3, offsets.data(), connectivity.data(), CYLVOL_INDEX_I64,
    connectivity.size(), sample.Types.data(), cells, &mesh);
  if (status != CYLVOL_STATUS_OK)
  {
    choice.Problem = "cylvol rejected the sampled cells: " + StatusText(status);
    return;
  }
  CylvolBuildParams params;
  cylvol_build_params_default(&params);
  params.structure = static_cast<CylvolStructure>(request.Structure);
  params.axis_auto = request.AxisAuto ? 1 : 0;
  std::copy(request.AxisOrigin, request.AxisOrigin + 3, params.axis_origin);
  std::copy(request.AxisDirection, request.AxisDirection + 3, params.axis_direction);
  CylvolVolume* volume = nullptr;
  status = cylvol_volume_new(mesh, &params, &volume);
  cylvol_mesh_free(mesh);
  CylvolBuildStats stats;
  double step = 0.0;
  if (status != CYLVOL_STATUS_OK ||
    cylvol_volume_build_stats(volume, &stats) != CYLVOL_STATUS_OK ||
    cylvol_volume_default_step(volume, &step) != CYLVOL_STATUS_OK)
  {
    choice.Problem = "cylvol could not build over the sampled cells: " + StatusText(status);
    cylvol_volume_free(volume);
    return;
  }
  cylvol_volume_free(volume);
  choice.Valid = true;
  choice.Structure = static_cast<int>(stats.structure);
  std::copy(stats.axis_origin, stats.axis_origin + 3, choice.AxisOrigin);
  std::copy(stats.axis_direction, stats.axis_direction + 3, choice.AxisDirection);
  choice.DefaultStep = step;
  choice.SampledCells = static_cast<double>(cells);
}

// Rank 0's choice on every rank.
void Broadcast(WholeDatasetChoice& choice, vtkMultiProcessController* controller)
{
  if (!controller || controller->GetNumberOfProcesses() <= 1)
  {
    return;
  }
  double packed[11] = { choice.Valid ? 1.0 : 0.0, static_cast<double>(choice.Structure),
    choice.AxisOrigin[0], choice.AxisOrigin[1], choice.AxisOrigin[2], choice.AxisDirection[0],
    choice.AxisDirection[1], choice.AxisDirection[2], choice.DefaultStep, choice.SampledCells,
    choice.TotalCells };
  controller->Broadcast(packed, 11, 0);
  choice.Valid = packed[0] != 0.0;
  choice.Structure = static_cast<int>(packed[1]);
  std::copy(packed + 2, packed + 5, choice.AxisOrigin);
  std::copy(packed + 5, packed + 8, choice.AxisDirection);
  choice.DefaultStep = packed[8];
  choice.SampledCells = packed[9];
  choice.TotalCells = packed[10];
}
} // namespace

WholeDatasetChoice ChooseForWholeDataset(vtkUnstructuredGrid* piece,
  const WholeDatasetRequest& request, vtkMultiProcessController* controller)
{
  if (controller && controller->GetNumberOfProcesses() <= 1)
  {
    controller = nullptr;
  }
  WholeDatasetChoice choice;
  const double local = CountTaken(piece);
  choice.TotalCells = local;
  if (controller)
  {
    controller->AllReduce(&local, &choice.TotalCells, 1, vtkCommunicator::SUM_OP);
  }
  const double fraction =
    choice.TotalCells > 0.0 ? std::min(1.0, kWholeDatasetSampleCells / choice.TotalCells) : 1.0;
  const CellList gathered = GatherOnFirstRank(LocalSample(piece, fraction), controller);
  if (!controller || controller->GetLocalProcessId() == 0)
  {
    BuildOverSample(Ordered(gathered), request, choice);
  }
  Broadcast(choice, controller);
  return choice;
}

} // namespace cylvolpv
