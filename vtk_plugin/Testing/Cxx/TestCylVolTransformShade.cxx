// Baseline: the combustor sector, shaded, placed by a volume matrix (rotated about two axes,
// scaled and moved), seen with a perspective camera framed on the moved volume.
#include "vtkCylVolMapper.h"

#include "vtkNew.h"
#include "vtkRegressionTestImage.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

int TestCylVolTransformShade(int argc, char* argv[])
{
  cylvoltest::Dataset d = cylvoltest::Load("comb");
  if (!d.Grid)
  {
    return EXIT_FAILURE;
  }
  vtkNew<vtkCylVolMapper> mapper;
  mapper->SetInputData(d.Grid);
  mapper->SetScalarModeToUsePointFieldData();
  mapper->SelectScalarArray(d.Scalar.c_str());
  auto property = cylvoltest::MakeProperty(d, true);
  property->SetSpecular(0.6);
  property->SetSpecularPower(40.0);

  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(property);
  volume->RotateX(-70.0);
  volume->RotateZ(25.0);
  volume->SetScale(1.0, 1.5, 1.0);
  volume->SetPosition(100.0, -40.0, 10.0);

  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  auto win = cylvoltest::MakeWindow(300, 300, ren);
  ren->SetBackground(0.1, 0.1, 0.15);
  cylvoltest::SetCamera(ren, 20.0, 10.0, 1.7);
  win->Render();
  const int result = vtkRegressionTestImageThreshold(win, 0.05);
  return result == vtkRegressionTester::FAILED ? EXIT_FAILURE : EXIT_SUCCESS;
}
