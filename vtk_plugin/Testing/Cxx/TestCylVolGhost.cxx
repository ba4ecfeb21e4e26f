// Ghost cells, as VTK marks them in the vtkGhostType cell array: the cells flagged as another
// piece's (DUPLICATECELL) or hidden (HIDDENCELL) are not drawn, as VTK's readers and
// vtkUnstructuredGrid::RemoveGhostCells drop them; other flags are drawn. On the mixer with
// point scalars and with cell scalars:
// - the mapper's image of the flagged grid equals its image of the grid VTK's
//   RemoveGhostCells leaves, and differs from the image of the grid without flags;
// - the input is left as it was (its cells and its ghost array);
// - the structure is built once while the input is unchanged, and again when the flags or the
//   points change; new scalar values and another array are handed over without a rebuild
//   (BuildCount stays, ScalarUpdateCount grows), and the image is the image of the grid
//   RemoveGhostCells leaves with those scalars.
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

// The mapper's image of `grid` (with `mapper`, new if null) as the dataset `d` is drawn, of
// the array `array` (d.Scalar if empty; d's point or cell data).
vtkSmartPointer<vtkImageData> Image(const cylvoltest::Dataset& d, vtkUnstructuredGrid* grid,
  vtkCylVolMapper* mapper = nullptr, const std::string& array = std::string())
{
  vtkNew<vtkCylVolMapper> own;
  vtkCylVolMapper* m = mapper ? mapper : own.Get();
  m->SetInputData(grid);
  if (d.Cells)
  {
    m->SetScalarModeToUseCellFieldData();
  }
  else
  {
    m->SetScalarModeToUsePointFieldData();
  }
  m->SelectScalarArray(array.empty() ? d.Scalar.c_str() : array.c_str());
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

  // Drawn again unchanged: no new build.
  int builds = mapper->GetBuildCount();
  Image(d, flagged, mapper);
  Expect(mapper->GetBuildCount() == builds, name + ": an unchanged input is not rebuilt");

  // New values of the scalars (mirrored in their range): handed over without a rebuild, and
  // the image is that of the grid without ghost cells with those values.
  vtkDataSetAttributes* attributes = d.Cells ? static_cast<vtkDataSetAttributes*>(flagged->GetCellData())
                                             : static_cast<vtkDataSetAttributes*>(flagged->GetPointData());
  vtkDataArray* values = attributes->GetArray(d.Scalar.c_str());
  for (vtkIdType i = 0; i < values->GetNumberOfTuples(); ++i)
  {
    values->SetComponent(i, 0, d.Range[0] + d.Range[1] - values->GetComponent(i, 0));
  }
  values->Modified();
  int updates = mapper->GetScalarUpdateCount();
  auto mirrored = Image(d, flagged, mapper);
  Expect(mapper->GetBuildCount() == builds, name + ": new scalar values are not rebuilt (" +
      std::to_string(mapper->GetBuildCount() - builds) + " builds)");
  Expect(mapper->GetScalarUpdateCount() == updates + 1, name + ": new scalar values are handed over");
  {
    auto removedMirrored = vtkSmartPointer<vtkUnstructuredGrid>::New();
    removedMirrored->DeepCopy(flagged);
    removedMirrored->RemoveGhostCells();
    Expect(cylvoltest::Compare(mirrored, Image(d, removedMirrored), 0).Within == 1.0,
      name + ": with new values the image is the image without ghost cells");
    Expect(cylvoltest::Compare(mirrored, ghosted, 2).Within < 0.99, name + ": and differs from the first");
  }

  // Another array (the first values, under a new name): no rebuild, the first image again.
  {
    vtkDataArray* first = (d.Cells ? static_cast<vtkDataSetAttributes*>(d.Grid->GetCellData())
                                   : static_cast<vtkDataSetAttributes*>(d.Grid->GetPointData()))
                            ->GetArray(d.Scalar.c_str());
    auto again = vtk::TakeSmartPointer(first->NewInstance());
    again->DeepCopy(first);
    again->SetName("again");
    attributes->AddArray(again);
    updates = mapper->GetScalarUpdateCount();
    auto other = Image(d, flagged, mapper, "again");
    Expect(mapper->GetBuildCount() == builds, name + ": another array is not rebuilt (" +
        std::to_string(mapper->GetBuildCount() - builds) + " builds)");
    Expect(mapper->GetScalarUpdateCount() == updates + 1, name + ": another array is handed over");
    Expect(cylvoltest::Compare(other, ghosted, 0).Within == 1.0,
      name + ": another array holding the first values draws the first image");
  }

  // Moved points rebuild.
  {
    double x[3];
    flagged->GetPoints()->GetPoint(0, x);
    x[0] += 1e-6 * d.Diagonal;
    flagged->GetPoints()->SetPoint(0, x);
    flagged->GetPoints()->Modified();
    Image(d, flagged, mapper);
    Expect(mapper->GetBuildCount() == builds + 1, name + ": moved points rebuild");
    builds = mapper->GetBuildCount();
  }

  // New flags: a new build and another image.
  vtkUnsignedCharArray* ghosts = flagged->GetCellGhostArray();
  for (vtkIdType c = 0; c < cells; ++c)
  {
    ghosts->SetValue(c, 0);
  }
  ghosts->Modified();
  auto cleared = Image(d, flagged, mapper);
  Expect(mapper->GetBuildCount() == builds + 1, name + ": new flags rebuild");
  Expect(cylvoltest::Compare(cleared, Image(d, flagged), 0).Within == 1.0,
    name + ": with the flags cleared the image is the whole grid's");
}
} // namespace

int TestCylVolGhost(int, char*[])
{
  Check("mixer");
  Check("mixer-cells");
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
