// One vtkUnstructuredGrid of the volume cells of any dataset ParaView's readers give (see
// CylVolVolumeCells.h).
#include "CylVolVolumeCells.h"

#include "vtkAppendFilter.h"
#include "vtkCellData.h"
#include "vtkCellTypes.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataSetAttributes.h"
#include "vtkExtractCells.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"
#include "vtkUnstructuredGrid.h"

#include <map>
#include <sstream>
#include <vector>

namespace cylvolpv
{
namespace
{
bool TakenByCylVol(int type)
{
  return type == VTK_HEXAHEDRON || type == VTK_VOXEL || type == VTK_WEDGE ||
    type == VTK_PYRAMID || type == VTK_TETRA;
}

// The dataset as an unstructured grid: itself (a shallow copy), or its cells as vtkAppendFilter
// makes them (a structured grid's hexahedra, an image's voxels).
vtkSmartPointer<vtkUnstructuredGrid> AsUnstructuredGrid(vtkDataSet* dataset)
{
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  if (auto ug = vtkUnstructuredGrid::SafeDownCast(dataset))
  {
    grid->ShallowCopy(ug);
    return grid;
  }
  vtkNew<vtkAppendFilter> convert;
  convert->AddInputData(dataset);
  convert->Update();
  grid->ShallowCopy(convert->GetOutput());
  return grid;
}

// The grid's cells of dimension 3 (the grid itself when it has no others).
vtkSmartPointer<vtkUnstructuredGrid> VolumeOnly(vtkUnstructuredGrid* grid)
{
  vtkNew<vtkIdList> kept;
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
  {
    if (vtkCellTypes::GetDimension(static_cast<unsigned char>(grid->GetCellType(c))) == 3)
    {
      kept->InsertNextId(c);
    }
  }
  if (kept->GetNumberOfIds() == grid->GetNumberOfCells())
  {
    return grid;
  }
  vtkNew<vtkExtractCells> extract;
  extract->SetInputData(grid);
  extract->SetCellList(kept);
  extract->Update();
  auto volume = vtkSmartPointer<vtkUnstructuredGrid>::New();
  volume->ShallowCopy(extract->GetOutput());
  return volume;
}

// The grid without the cells its ghost array flags as another piece's or hidden, and without
// the ghost array.
void RemoveGhostCells(vtkUnstructuredGrid* grid)
{
  vtkUnsignedCharArray* ghosts = grid->GetCellGhostArray();
  if (!ghosts)
  {
    return;
  }
  const unsigned char flags = vtkDataSetAttributes::DUPLICATECELL | vtkDataSetAttributes::HIDDENCELL;
  bool any = false;
  for (vtkIdType c = 0; c < ghosts->GetNumberOfTuples() && !any; ++c)
  {
    any = (ghosts->GetValue(c) & flags) != 0;
  }
  if (any)
  {
    grid->RemoveGhostCells();
  }
  grid->GetCellData()->RemoveArray(vtkDataSetAttributes::GhostArrayName());
}

std::string DescribeUnsupported(vtkUnstructuredGrid* grid)
{
  std::map<int, long long> counts;
  for (vtkIdType c = 0; c < grid->GetNumberOfCells(); ++c)
  {
    const int type = grid->GetCellType(c);
    if (!TakenByCylVol(type))
    {
      counts[type]++;
    }
  }
  std::ostringstream text;
  for (const auto& entry : counts)
  {
    const char* name = vtkCellTypes::GetClassNameFromTypeId(entry.first);
    text << (text.tellp() > 0 ? ", " : "") << entry.second << " " << (name ? name : "unknown")
         << " (type " << entry.first << ")";
  }
  return text.str();
}
} // namespace

VolumeCells GatherVolumeCells(vtkDataObject* input)
{
  VolumeCells out;
  out.Grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  if (!input)
  {
    return out;
  }
  std::vector<vtkSmartPointer<vtkUnstructuredGrid>> blocks;
  for (vtkDataSet* dataset : vtkCompositeDataSet::GetDataSets(input))
  {
    if (!dataset)
    {
      continue;
    }
    out.InputCells += dataset->GetNumberOfCells();
    if (vtkPolyData::SafeDownCast(dataset) || dataset->GetNumberOfCells() == 0)
    {
      continue;
    }
    // A copy of the dataset's own (shares its arrays), so that removing ghost cells and the
    // ghost array leaves the input as it is.
    vtkSmartPointer<vtkUnstructuredGrid> grid = VolumeOnly(AsUnstructuredGrid(dataset));
    RemoveGhostCells(grid);
    if (grid->GetNumberOfCells() > 0)
    {
      blocks.push_back(grid);
    }
  }
  if (blocks.size() == 1)
  {
    out.Grid = blocks[0];
  }
  else if (blocks.size() > 1)
  {
    vtkNew<vtkAppendFilter> append;
    for (const auto& block : blocks)
    {
      append->AddInputData(block);
    }
    append->Update();
    out.Grid->ShallowCopy(append->GetOutput());
  }
  out.Unsupported = DescribeUnsupported(out.Grid);
  return out;
}

} // namespace cylvolpv
