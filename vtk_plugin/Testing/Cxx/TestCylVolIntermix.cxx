// Baseline: the synthetic pump rotor (from the CTest fixture) intermixed with opaque
// polygonal geometry: a sphere cutting through the volume, a cone in front of part of it and
// a cylinder behind it. The rays stop at the z-buffer of what is already drawn.
#include "vtkCylVolMapper.h"

#include "vtkActor.h"
#include "vtkConeSource.h"
#include "vtkCylinderSource.h"
#include "vtkNew.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRegressionTestImage.h"
#include "vtkSphereSource.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

namespace
{
void AddActor(vtkRenderer* ren, vtkAlgorithm* source, double r, double g, double b)
{
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(source->GetOutputPort());
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(r, g, b);
  ren->AddActor(actor);
}
} // namespace

int TestCylVolIntermix(int argc, char* argv[])
{
  cylvoltest::Dataset d = cylvoltest::Load("pump");
  if (!d.Grid)
  {
    return EXIT_FAILURE;
  }
  vtkNew<vtkCylVolMapper> mapper;
  mapper->SetInputData(d.Grid);
  auto property = cylvoltest::MakeProperty(d, false);
  vtkNew<vtkVolume> volume;
  volume->SetMapper(mapper);
  volume->SetProperty(property);

  vtkNew<vtkRenderer> ren;
  ren->AddVolume(volume);
  vtkNew<vtkSphereSource> sphere;
  sphere->SetCenter(0.55, 0.0, 0.225);
  sphere->SetRadius(0.3);
  sphere->SetThetaResolution(48);
  sphere->SetPhiResolution(24);
  AddActor(ren, sphere, 0.9, 0.9, 0.9);
  vtkNew<vtkConeSource> cone;
  cone->SetCenter(-0.5, -0.5, 1.0);
  cone->SetDirection(0, 0, 1);
  cone->SetHeight(0.5);
  cone->SetRadius(0.2);
  cone->SetResolution(32);
  AddActor(ren, cone, 0.2, 0.9, 0.3);
  vtkNew<vtkCylinderSource> cylinder;
  cylinder->SetCenter(0.0, 0.0, -0.5);
  cylinder->SetRadius(0.15);
  cylinder->SetHeight(2.5);
  cylinder->SetResolution(32);
  AddActor(ren, cylinder, 0.9, 0.5, 0.2);

  auto win = cylvoltest::MakeWindow(300, 300, ren);
  ren->SetBackground(0.1, 0.1, 0.15);
  ren->ResetCamera();
  vtkCamera* cam = ren->GetActiveCamera();
  cam->Elevation(55.0);
  cam->OrthogonalizeViewUp();
  cam->Azimuth(20.0);
  cam->Zoom(1.3);
  ren->ResetCameraClippingRange();
  win->Render();
  const int result = vtkRegressionTestImageThreshold(win, 0.05);
  return result == vtkRegressionTester::FAILED ? EXIT_FAILURE : EXIT_SUCCESS;
}
