// The settings every rank's vtkCylVolMapper shares, chosen once from the whole dataset: the
// structure (AUTO's choice made), the machine axis, and the default sample distance.
//
// Each rank holds a piece of the dataset. A rank's piece alone would give its own axis,
// structure and step, and ranks with different steps draw seams where their boxes meet. So
// the ranks take an even sample of the whole dataset's cells, chosen by a hash of each cell's
// centre (the same cells whichever rank holds them, and however the dataset is split), gather
// it on the first rank in the order of that hash, and let cylvol build a volume over it
// (cylvol_volume_new with the user's structure and axis settings): the structure, axis and
// default step of that volume are broadcast to every rank. One rank gives the same answer
// as any number of ranks for the same dataset.
#ifndef CylVolWholeDataset_h
#define CylVolWholeDataset_h

#include <string>

class vtkMultiProcessController;
class vtkUnstructuredGrid;

namespace cylvolpv
{

/// What the user asked for (the mapper's settings of the same names).
struct WholeDatasetRequest
{
  int Structure = 0; // CylvolStructure: 0 AUTO
  bool AxisAuto = true;
  double AxisOrigin[3] = { 0.0, 0.0, 0.0 };
  double AxisDirection[3] = { 0.0, 0.0, 1.0 };
};

/// The choice every rank applies. Valid is false when the whole dataset has no cell cylvol
/// takes, or cylvol refused the sample (Problem says why, on the first rank).
struct WholeDatasetChoice
{
  bool Valid = false;
  int Structure = 0; // never AUTO when valid
  double AxisOrigin[3] = { 0.0, 0.0, 0.0 };
  double AxisDirection[3] = { 0.0, 0.0, 1.0 };
  double DefaultStep = 0.0;
  double SampledCells = 0.0; // cells in the sample
  double TotalCells = 0.0;   // cells of the whole dataset
  std::string Problem;
};

/// The cells sampled from a dataset of this many cells, about (all of them up to it).
constexpr double kWholeDatasetSampleCells = 32768.0;

/// Collective over `controller` (every rank calls it; null means this process alone): the
/// choice for the dataset whose pieces the ranks hold in `piece` (null or empty on ranks
/// without cells). Cells of types cylvol does not take are left out of the sample.
WholeDatasetChoice ChooseForWholeDataset(vtkUnstructuredGrid* piece,
  const WholeDatasetRequest& request, vtkMultiProcessController* controller);

} // namespace cylvolpv

#endif
