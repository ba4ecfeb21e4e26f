// Shading and gradient opacity with cell scalars, on the mixer. Cell scalars are constant in
// each cell, so their gradient is zero: a gradient opacity function that is 0 at 0 would hide
// the whole volume, and shading has no normal. VTK's unstructured mappers shade nothing and
// apply no gradient opacity; vtkCylVolMapper does the same for cell scalars, with a warning:
// - cell p, shading on and a gradient opacity function rising from 0 at gradient 0: the image
//   is that of the same scene without either (so not empty), no gradient is evaluated, and one
//   warning names both;
// - drawn again, no new warning; with shading off, one new warning naming gradient opacity only;
// - point p in the same scene is shaded and weighed by its gradient (gradients evaluated, the
//   image differs from the plain one) and raises no warning.
#include "vtkCylVolMapper.h"

#include "vtkCallbackCommand.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
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

int warnings = 0;
std::string lastWarning;
void OnWarning(vtkObject*, unsigned long, void*, void* callData)
{
  warnings++;
  lastWarning = static_cast<const char*>(callData);
}

// A scene: `mapper` draws `d` through `property`.
struct Scene
{
  vtkNew<vtkVolume> Volume;
  vtkNew<vtkRenderer> Ren;
  vtkSmartPointer<vtkRenderWindow> Win;

  Scene(const cylvoltest::Dataset& d, vtkCylVolMapper* mapper, vtkVolumeProperty* property)
  {
    mapper->SetInputData(d.Grid);
    if (d.Cells)
    {
      mapper->SetScalarModeToUseCellFieldData();
    }
    else
    {
      mapper->SetScalarModeToUsePointFieldData();
    }
    mapper->SelectScalarArray(d.Scalar.c_str());
    this->Volume->SetMapper(mapper);
    this->Volume->SetProperty(property);
    this->Ren->AddVolume(this->Volume);
    this->Win = cylvoltest::MakeWindow(160, 160, this->Ren);
    cylvoltest::SetCamera(this->Ren, 30, 20, 1.2);
  }

  vtkSmartPointer<vtkImageData> Draw()
  {
    this->Win->Render();
    return cylvoltest::Grab(this->Win);
  }
};

// `d`'s transfer functions, shaded or not, with or without a gradient opacity function that is
// 0 at gradient 0 and 1 from a tenth of the range over the mesh's diagonal.
vtkSmartPointer<vtkVolumeProperty> Property(const cylvoltest::Dataset& d, bool shade, bool gradient)
{
  auto property = cylvoltest::MakeProperty(d, shade);
  if (gradient)
  {
    vtkNew<vtkPiecewiseFunction> go;
    go->AddPoint(0.0, 0.0);
    go->AddPoint(0.1 * (d.Range[1] - d.Range[0]) / d.Diagonal, 1.0);
    property->SetGradientOpacity(go);
  }
  return property;
}
} // namespace

int TestCylVolCellGradient(int, char*[])
{
  vtkNew<vtkCallbackCommand> onWarning;
  onWarning->SetCallback(OnWarning);

  cylvoltest::Dataset cells = cylvoltest::Load("mixer-cells");
  cylvoltest::Dataset points = cylvoltest::Load("mixer");
  if (!cells.Grid || !points.Grid)
  {
    return EXIT_FAILURE;
  }

  // Cell scalars.
  vtkNew<vtkCylVolMapper> plainMapper;
  auto plain = Scene(cells, plainMapper, Property(cells, false, false)).Draw();
  vtkNew<vtkCylVolMapper> mapper;
  mapper->AddObserver(vtkCommand::WarningEvent, onWarning);
  auto property = Property(cells, true, true);
  Scene scene(cells, mapper, property);
  auto both = scene.Draw();
  Expect(cylvoltest::Lit(both) > 1000, "cell scalars, shading and gradient opacity: the volume is drawn (" +
      std::to_string(cylvoltest::Lit(both)) + " pixels lit)");
  Expect(cylvoltest::Compare(both, plain, 0).Within == 1.0,
    "cell scalars: the image is the one without shading or gradient opacity");
  Expect(mapper->GetLastGradientEvaluations() == 0, "cell scalars: no gradient evaluated");
  Expect(warnings == 1 && lastWarning.find("shading and the gradient opacity function are left out") !=
        std::string::npos,
    "cell scalars: one warning naming both (" + std::to_string(warnings) + ")");
  if (!lastWarning.empty())
  {
    std::string shown = lastWarning.substr(lastWarning.find("vtkCylVolMapper ("));
    shown.erase(shown.find_last_not_of(" \n") + 1);
    std::cout << "       warning: " << shown << "\n";
  }
  scene.Ren->GetActiveCamera()->Azimuth(10);
  scene.Draw();
  Expect(warnings == 1, "cell scalars, drawn again: no new warning");
  property->ShadeOff();
  auto gradientOnly = scene.Draw();
  Expect(warnings == 2 && lastWarning.find("the gradient opacity function is left out") != std::string::npos &&
      lastWarning.find("shading") == std::string::npos,
    "cell scalars, shading turned off: a new warning naming the gradient opacity alone");
  Expect(cylvoltest::Lit(gradientOnly) > 1000, "cell scalars, gradient opacity alone: the volume is drawn");

  // Point scalars in the same scene: shaded and weighed by their gradient, without a warning.
  warnings = 0;
  vtkNew<vtkCylVolMapper> pointPlainMapper;
  auto pointPlain = Scene(points, pointPlainMapper, Property(points, false, false)).Draw();
  vtkNew<vtkCylVolMapper> pointMapper;
  pointMapper->AddObserver(vtkCommand::WarningEvent, onWarning);
  auto pointBoth = Scene(points, pointMapper, Property(points, true, true)).Draw();
  Expect(warnings == 0, "point scalars: no warning");
  Expect(pointMapper->GetLastGradientEvaluations() > 0, "point scalars: gradients evaluated");
  Expect(cylvoltest::Compare(pointBoth, pointPlain, 2).Within < 0.99,
    "point scalars: shading and gradient opacity change the image");
  return failures == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
