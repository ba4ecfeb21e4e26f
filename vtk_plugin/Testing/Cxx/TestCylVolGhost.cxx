// Ghost cells, as VTK marks them in the vtkGhostType cell array: the cells flagged as another
// piece's (DUPLICATECELL) or hidden (HIDDENCELL) are not drawn, as VTK's readers and
// vtkUnstructuredGrid::RemoveGhostCells drop them; other flags are drawn. On the mixer with
// point scalars and with cell scalars:
// - the mapper's image of the flagged grid equals its image of the grid VTK's
//   RemoveGhostCells leaves, and differs from the image of the grid without flags;
// - the input is left as it was (its cells and its ghost array);
// - the structure is built once while the input is unchanged, and again when the flags change.
#include "vtkCylVolMapper.h"

#include "vtkCellData.h"
#include "vtkDataSetAttributes.h"
#include "vtkNew.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

namespace
{
int failures = 0;
void Expect(bool condition, const std::string& what)
{
  std::cout << (condition ? "ok   " : "FAIL ") << what << "\n";
  failures += condition ? 0 : 1;
}

// A copy of `grid` whose cells carry ghost flags: every 3rd another piece's, every 7th hidden,
// every 5th refined (drawn).
vtkSmartPointer<vtkUnstructuredGrid> Flagged(vtkUnstructuredGrid* grid)
{
  auto flagged = vtkSmartPointer<vtkUnstructuredGrid>::New();
  flagged->DeepCopy(grid);
  vtkUnsignedCharArray* ghosts = flagged->AllocateCellGhostArray();
  for (vtkIdType c = 0; c < flagged->GetNumberOfCells(); ++c)
  {
    unsigned char flag = 0;
    flag |= c % 3 == 0 ? vtkDataSetAttributes::DUPLICATECELL : 0;
    flag |= c % 7 == 0 ? vtkDataSetAttributes::HIDDENCELL : 0;
    flag |= c % 5 == 0 ? vtkDataSetAttributes::REFINEDCELL : 0;
    ghosts->SetValue(c, flag);
  }
  return flagged;
}

// The mapper's image of `grid` (with `mapper`, new if null) as the dataset `d` is drawn.
vtkSmartPointer<vtkImageData> Image(const cylvoltest::Dataset& d, vtkUnstructuredGrid* grid,
  vtkCylVolMapper* mapper = nullptr)
{
  vtkNew<vtkCylVolMapper> own;
  vtkCylVolMapper* m = mapper ? mapper : own.Get();
  m->SetInputData(grid);
  if (d.Cells)
  {
    m->SetScalarModeToUseCellFieldData();
    m->SelectScalarArray(d.Scalar.c_str());
  }
  vtkNew<vtkVolume> volume;
  volume->SetMapper(m);
  volume->SetProperty(cylvoltest::MakeProperty(d, false));
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  auto win = cylvoltest::MakeWindow(160, 160, ren);
  cylvoltest::SetCamera(ren, 30, 20, 1.2);
  win->Render();
  return cylvoltest::Grab(win);
}

void Check(const std::string& name)
{
  cylvoltest::Dataset d = cylvoltest::Load(name);
  if (!d.Grid)
  {
    failures++;
    return;
  }
  auto flagged = Flagged(d.Grid);
  const vtkIdType cells = flagged->GetNumberOfCells();
  auto removed = vtkSmartPointer<vtkUnstructuredGrid>::New();
  removed->DeepCopy(flagged);
  removed->RemoveGhostCells();
  Expect(removed->GetNumberOfCells() < cells * 2 / 3, name + ": VTK removes the flagged cells");

  vtkNew<vtkCylVolMapper> mapper;
  auto ghosted = Image(d, flagged, mapper);
  auto reference = Image(d, removed);
  auto whole = Image(d, d.Grid);
  const cylvoltest::Agreement same = cylvoltest::Compare(ghosted, reference, 0);
  Expect(same.Within == 1.0, name + ": the flagged grid's image is the image without its ghost cells (" +
      std::to_string(same.Within) + " of pixels equal)");
  const cylvoltest::Agreement differs = cylvoltest::Compare(ghosted, whole, 2);
  Expect(differs.Within < 0.99, name + ": and not the whole grid's (" + std::to_string(differs.Within) +
      " of pixels within 2/255)");
  Expect(flagged->GetNumberOfCells() == cells && flagged->GetCellGhostArray() &&
      flagged->GetCellGhostArray()->GetValue(0) == (vtkDataSetAttributes::DUPLICATECELL |
        vtkDataSetAttributes::HIDDENCELL | vtkDataSetAttributes::REFINEDCELL),
    name + ": the input keeps its cells and flags");

  // Drawn again unchanged: no new build; new flags: a new build and another image.
  const int builds = mapper->GetBuildCount();
  Image(d, flagged, mapper);
  Expect(mapper->GetBuildCount() == builds, name + ": an unchanged input is not rebuilt");
  vtkUnsignedCharArray* ghosts = flagged->GetCellGhostArray();
  for (vtkIdType c = 0; c < cells; ++c)
  {
    ghosts->SetValue(c, 0);
  }
  ghosts->Modified();
  auto cleared = Image(d, flagged, mapper);
  Expect(mapper->GetBuildCount() == builds + 1, name + ": new flags rebuild");
  Expect(cylvoltest::Compare(cleared, whole, 0).Within == 1.0,
    name + ": with the flags cleared the image is the whole grid's");
}
} // namespace

int TestCylVolGhost(int, char*[])
{
  Check("mixer");
  Check("mixer-cells");
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
