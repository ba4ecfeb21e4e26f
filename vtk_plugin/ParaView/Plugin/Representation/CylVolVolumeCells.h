// The volume a "CylVol Volume" representation draws, as one vtkUnstructuredGrid: the cells of
// dimension 3 of whatever ParaView's readers give (an unstructured grid, a structured grid,
// image or rectilinear blocks, or a multiblock or partitioned dataset of any of them), the
// blocks appended one after another with their own points (hexahedra stay hexahedra, nothing
// is split), without the cells the data's ghost array flags as another piece's or hidden.
// Surfaces, lines and points (polydata blocks, a reader's boundary patches, 2D cells) are not
// part of the volume and are left out.
#ifndef CylVolVolumeCells_h
#define CylVolVolumeCells_h

#include "vtkSmartPointer.h"

#include <string>

class vtkDataObject;
class vtkUnstructuredGrid;

namespace cylvolpv
{

struct VolumeCells
{
  /// The volume cells (never null; empty when there are none).
  vtkSmartPointer<vtkUnstructuredGrid> Grid;
  /// Volume cells of types cylvol does not take, by name and count ("12 vtkPolyhedron (type
  /// 42)"), empty when there are none. Grid then still holds them.
  std::string Unsupported;
  /// How many cells the input had in all (volume or not, ghost cells included).
  long long InputCells = 0;
};

/// The volume cells of `input` (null gives none).
VolumeCells GatherVolumeCells(vtkDataObject* input);

} // namespace cylvolpv

#endif
