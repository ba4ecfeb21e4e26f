// Multi-component scalars and vtkVolumeProperty's IndependentComponents, on the mixer's
// 3-component velocity U (point and cell data). VTK's unstructured mappers draw every component
// through its own transfer functions and mix them (IndependentComponents on), or read 2 or 4
// components as colour and opacity (off); vtkCylVolMapper draws one component:
// - IndependentComponents on, no component chosen: an error that says so and how to choose
//   one, nothing drawn, nothing built;
// - on, component 1 chosen: the image of a one-component array holding U's component 1;
// - on, SCALAR_MAGNITUDE: the image of a one-component array holding |U|;
// - off: an error naming IndependentComponents, nothing drawn, nothing built, whichever
//   component is chosen;
// - a one-component array draws the same image with IndependentComponents off as on, and
//   with SCALAR_MAGNITUDE as with no component chosen (its values, not their magnitude).
// Each build records the cells it was given by type (GetBuiltCellCount): the mixer's
// hexahedra, and no other cell.
#include "vtkCylVolMapper.h"

#include "vtkCellData.h"
#include "vtkFloatArray.h"
#include "vtkNew.h"
#include "vtkTestErrorObserver.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

#include <cmath>

namespace
{
int failures = 0;
void Expect(bool condition, const std::string& what)
{
  std::cout << (condition ? "ok   " : "FAIL ") << what << "\n";
  failures += condition ? 0 : 1;
}

struct Result
{
  vtkSmartPointer<vtkImageData> Image;
  vtkIdType Lit = 0;
  std::string Error; // empty: none
  int Builds = 0;
  vtkIdType Hexahedra = 0;
  vtkIdType OtherCells = 0; // of any other type
};

// Draws `array` of `grid` (cell data when `cells`) with a fresh mapper, component `component`
// (-1: none chosen; SCALAR_MAGNITUDE), IndependentComponents `independent`, through `d`'s
// transfer functions.
Result Draw(const cylvoltest::Dataset& d, vtkUnstructuredGrid* grid, const char* array, bool cells,
  int component, bool independent)
{
  vtkNew<vtkCylVolMapper> mapper;
  vtkNew<vtkTest::ErrorObserver> errors;
  mapper->AddObserver(vtkCommand::ErrorEvent, errors);
  mapper->SetInputData(grid);
  if (cells)
  {
    mapper->SetScalarModeToUseCellFieldData();
  }
  else
  {
    mapper->SetScalarModeToUsePointFieldData();
  }
  mapper->SelectScalarArray(array);
  mapper->SetScalarComponent(component);
  auto property = cylvoltest::MakeProperty(d, false);
  property->SetIndependentComponents(independent ? 1 : 0);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(property);
  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  auto win = cylvoltest::MakeWindow(160, 160, ren);
  cylvoltest::SetCamera(ren, 30, 20, 1.2);
  win->Render();
  Result r;
  r.Image = cylvoltest::Grab(win);
  r.Lit = cylvoltest::Lit(r.Image);
  if (errors->GetError())
  {
    r.Error = errors->GetErrorMessage();
    // Printed without VTK's "ERROR: " prefix, which CTest would take for a failure.
    for (size_t at = r.Error.find("ERROR: "); at != std::string::npos; at = r.Error.find("ERROR: "))
    {
      r.Error.replace(at, 7, "error: ");
    }
  }
  r.Builds = mapper->GetBuildCount();
  r.Hexahedra = mapper->GetBuiltCellCount(VTK_HEXAHEDRON);
  for (int type = 0; type < 256; ++type)
  {
    r.OtherCells += type == VTK_HEXAHEDRON ? 0 : mapper->GetBuiltCellCount(type);
  }
  return r;
}

bool Refused(const Result& r, const std::string& needle)
{
  if (!r.Error.empty())
  {
    std::string message = r.Error.substr(r.Error.find("vtkCylVolMapper ("));
    message.erase(message.find_last_not_of(" \n") + 1);
    std::cout << "       message: " << message << "\n";
  }
  return r.Error.find(needle) != std::string::npos && r.Lit == 0 && r.Builds == 0;
}

void Check(bool cells)
{
  const std::string name = cells ? "cell U" : "point U";
  cylvoltest::Dataset d = cylvoltest::Load(cells ? "mixer-cells" : "mixer");
  if (!d.Grid)
  {
    failures++;
    return;
  }
  vtkDataSetAttributes* attributes = cells ? static_cast<vtkDataSetAttributes*>(d.Grid->GetCellData())
                                           : static_cast<vtkDataSetAttributes*>(d.Grid->GetPointData());
  vtkDataArray* u = attributes->GetArray("U");
  if (!u || u->GetNumberOfComponents() != 3)
  {
    std::cout << "FAIL " << name << ": the mixer has no 3-component U\n";
    failures++;
    return;
  }
  // U's component 1 alone, as floats like U.
  vtkNew<vtkFloatArray> u1;
  u1->SetName("U1");
  u1->SetNumberOfTuples(u->GetNumberOfTuples());
  for (vtkIdType i = 0; i < u->GetNumberOfTuples(); ++i)
  {
    u1->SetValue(i, static_cast<float>(u->GetComponent(i, 1)));
  }
  attributes->AddArray(u1);
  cylvoltest::Dataset du = d;
  u->GetRange(du.Range, 1);

  const Result none = Draw(du, d.Grid, "U", cells, -1, true);
  Expect(Refused(none, "no valid component is chosen") &&
      none.Error.find("IndependentComponents") != std::string::npos &&
      none.Error.find("SetScalarComponent(0..2)") != std::string::npos,
    name + ", independent, no component: refused, says how to choose one, nothing drawn or built");

  const Result one = Draw(du, d.Grid, "U", cells, 1, true);
  const Result alone = Draw(du, d.Grid, "U1", cells, -1, true);
  Expect(one.Error.empty() && one.Lit > 1000, name + ", independent, component 1: drawn (" +
      std::to_string(one.Lit) + " pixels lit)");
  Expect(alone.Error.empty() && cylvoltest::Compare(one.Image, alone.Image, 0).Within == 1.0,
    name + ", component 1 draws the image of U's component 1 alone");

  // |U|, as floats like U.
  vtkNew<vtkFloatArray> magnitude;
  magnitude->SetName("Umag");
  magnitude->SetNumberOfTuples(u->GetNumberOfTuples());
  for (vtkIdType i = 0; i < u->GetNumberOfTuples(); ++i)
  {
    double t[3];
    u->GetTuple(i, t);
    magnitude->SetValue(i, static_cast<float>(std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2])));
  }
  attributes->AddArray(magnitude);
  cylvoltest::Dataset dm = d;
  u->GetRange(dm.Range, -1);
  const Result norm = Draw(dm, d.Grid, "U", cells, vtkCylVolMapper::SCALAR_MAGNITUDE, true);
  const Result normAlone = Draw(dm, d.Grid, "Umag", cells, -1, true);
  const cylvoltest::Agreement normAgreement = cylvoltest::Compare(norm.Image, normAlone.Image, 1);
  Expect(norm.Error.empty() && norm.Lit > 1000 && normAgreement.Within >= 0.999,
    name + ", independent, SCALAR_MAGNITUDE: the image of |U| alone (" +
      std::to_string(100.0 * normAgreement.Within) + " % of pixels within 1/255)");
  Expect(norm.Hexahedra == d.Grid->GetNumberOfCells() && norm.OtherCells == 0,
    name + ": the structure was built over the mixer's " + std::to_string(norm.Hexahedra) +
      " hexahedra and no other cell");

  for (int component : { -1, 1 })
  {
    const Result dependent = Draw(du, d.Grid, "U", cells, component, false);
    Expect(Refused(dependent, "has 3 components and the volume property's IndependentComponents is off"),
      name + ", IndependentComponents off, component " + std::to_string(component) +
        ": refused, nothing drawn or built");
  }

  const Result single = Draw(d, d.Grid, d.Scalar.c_str(), cells, -1, true);
  const Result singleOff = Draw(d, d.Grid, d.Scalar.c_str(), cells, -1, false);
  Expect(single.Error.empty() && singleOff.Error.empty() && single.Lit > 1000 &&
      cylvoltest::Compare(single.Image, singleOff.Image, 0).Within == 1.0,
    name + ": one component (p) draws the same image with IndependentComponents off");
  const Result singleNorm = Draw(d, d.Grid, d.Scalar.c_str(), cells,
    vtkCylVolMapper::SCALAR_MAGNITUDE, true);
  Expect(singleNorm.Error.empty() &&
      cylvoltest::Compare(single.Image, singleNorm.Image, 0).Within == 1.0,
    name + ": one component (p) draws its values with SCALAR_MAGNITUDE too");
}
} // namespace

int TestCylVolComponents(int, char*[])
{
  Check(false);
  Check(true);
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
