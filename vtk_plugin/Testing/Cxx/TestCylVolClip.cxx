// Baseline: the mixer placed by a volume matrix (moved and turned about two axes) and cut
// open by a clipping plane through its centre, given in world coordinates. Also checks, with
// no baseline:
// - a plane that keeps the whole volume changes neither the image nor the samples taken;
// - the cut volume takes fewer samples, and equals the same plane applied to the grid moved
//   beforehand (vtkTransformFilter) and drawn with no matrix: the plane reaches the mapper in
//   the data's coordinates;
// - more clipping planes than cylvol takes are an error naming them, and nothing is drawn.
#include "vtkCylVolMapper.h"

#include "vtkCamera.h"
#include "vtkNew.h"
#include "vtkPlane.h"
#include "vtkRegressionTestImage.h"
#include "vtkTestErrorObserver.h"
#include "vtkTransform.h"
#include "vtkTransformFilter.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

namespace
{
struct Scene
{
  vtkNew<vtkCylVolMapper> Mapper;
  vtkNew<vtkVolume> Volume;
  vtkNew<vtkRenderer> Ren;
  vtkSmartPointer<vtkRenderWindow> Win;

  Scene(const cylvoltest::Dataset& d, vtkDataSet* grid)
  {
    this->Mapper->SetInputData(grid);
    this->Mapper->SetScalarModeToUsePointFieldData();
    this->Mapper->SelectScalarArray(d.Scalar.c_str());
    this->Volume->SetMapper(this->Mapper);
    // Ten times denser than the comparison scene's, so that the cut face shows.
    auto property = cylvoltest::MakeProperty(d, false);
    property->SetScalarOpacityUnitDistance(0.01 * d.Diagonal);
    this->Volume->SetProperty(property);
    this->Ren->AddVolume(this->Volume);
    this->Win = cylvoltest::MakeWindow(300, 300, this->Ren);
  }

  vtkSmartPointer<vtkImageData> Render()
  {
    this->Win->Render();
    return cylvoltest::Grab(this->Win);
  }
};

vtkSmartPointer<vtkPlane> Plane(const double origin[3], const double normal[3])
{
  auto plane = vtkSmartPointer<vtkPlane>::New();
  plane->SetOrigin(origin[0], origin[1], origin[2]);
  plane->SetNormal(normal[0], normal[1], normal[2]);
  return plane;
}
}

int TestCylVolClip(int argc, char* argv[])
{
  cylvoltest::Dataset d = cylvoltest::Load("mixer");
  if (!d.Grid)
  {
    return EXIT_FAILURE;
  }
  vtkNew<vtkTransform> placement;
  placement->Translate(0.3, -0.1, 0.05);
  placement->RotateX(-60.0);
  placement->RotateZ(25.0);

  Scene placed(d, d.Grid);
  placed.Volume->SetUserTransform(placement);
  placed.Ren->SetBackground(0.1, 0.1, 0.15);
  cylvoltest::SetCamera(placed.Ren, 20.0, 15.0, 1.3);
  auto whole = placed.Render();
  const vtkTypeUInt64 allSamples = placed.Mapper->GetLastSamplesLocated();

  // The plane through the volume's centre (world coordinates), and one parallel to it beyond
  // the volume's bounds on its far side, which keeps all of it.
  double centre[3];
  const double* c = placed.Volume->GetCenter();
  std::copy(c, c + 3, centre);
  const double normal[3] = { 1.0, 0.4, -0.3 };
  const double far = 2.0 * placed.Volume->GetLength();
  const double behind[3] = { centre[0] - far * normal[0], centre[1] - far * normal[1],
    centre[2] - far * normal[2] };
  placed.Mapper->AddClippingPlane(Plane(behind, normal));
  auto kept = placed.Render();
  if (cylvoltest::Compare(whole, kept, 0).Within != 1.0 ||
    placed.Mapper->GetLastSamplesLocated() != allSamples)
  {
    std::cerr << "a plane keeping the whole volume changed the image or the samples ("
              << placed.Mapper->GetLastSamplesLocated() << " vs " << allSamples << ")\n";
    return EXIT_FAILURE;
  }

  placed.Mapper->RemoveAllClippingPlanes();
  placed.Mapper->AddClippingPlane(Plane(centre, normal));
  auto cut = placed.Render();
  const vtkTypeUInt64 cutSamples = placed.Mapper->GetLastSamplesLocated();
  if (!(cutSamples > 0 && cutSamples < allSamples * 4 / 5))
  {
    std::cerr << "the cut volume took " << cutSamples << " samples of " << allSamples << "\n";
    return EXIT_FAILURE;
  }
  if (cylvoltest::Compare(whole, cut, 8).Within > 0.95)
  {
    std::cerr << "the plane hardly changed the image\n";
    return EXIT_FAILURE;
  }

  // The grid moved beforehand and drawn without a matrix, seen by the same camera and cut by
  // the same world plane: the same picture (up to the moved points' float rounding).
  vtkNew<vtkTransformFilter> move;
  move->SetInputData(d.Grid);
  move->SetTransform(placement);
  move->Update();
  Scene moved(d, move->GetOutput());
  moved.Ren->SetBackground(0.1, 0.1, 0.15);
  moved.Ren->SetActiveCamera(placed.Ren->GetActiveCamera());
  moved.Mapper->AddClippingPlane(Plane(centre, normal));
  auto movedCut = moved.Render();
  const cylvoltest::Agreement a = cylvoltest::Compare(cut, movedCut, 2);
  if (a.Within < 0.99)
  {
    std::cerr << "matrix and moved grid disagree: " << 100.0 * a.Within
              << " % of pixels within 2/255, mean " << a.Mean << "/255\n";
    cylvoltest::WritePNG(cut, cylvoltest::OutputPath("TestCylVolClip-matrix.png"));
    cylvoltest::WritePNG(movedCut, cylvoltest::OutputPath("TestCylVolClip-moved.png"));
    return EXIT_FAILURE;
  }

  // Seven planes: an error naming the count, nothing drawn.
  vtkNew<vtkTest::ErrorObserver> errors;
  moved.Mapper->AddObserver(vtkCommand::ErrorEvent, errors);
  for (int i = 0; i < 6; ++i)
  {
    moved.Mapper->AddClippingPlane(Plane(behind, normal));
  }
  auto refused = moved.Render();
  const std::string message = errors->GetErrorMessage();
  if (!errors->GetError() || message.find("clip_plane_count = 7") == std::string::npos)
  {
    std::cerr << "seven planes: expected an error naming them, got '" << message << "'\n";
    return EXIT_FAILURE;
  }
  const unsigned char* px =
    static_cast<unsigned char*>(refused->GetPointData()->GetScalars()->GetVoidPointer(0));
  for (vtkIdType i = 0; i < refused->GetNumberOfPoints(); ++i)
  {
    // The background (0.1, 0.1, 0.15) and nothing else.
    if (px[3 * i] > 26 || px[3 * i + 1] > 26 || px[3 * i + 2] > 39)
    {
      std::cerr << "seven planes: pixel " << i << " drawn\n";
      return EXIT_FAILURE;
    }
  }

  const int result = vtkRegressionTestImageThreshold(placed.Win, 0.05);
  return result == vtkRegressionTester::FAILED ? EXIT_FAILURE : EXIT_SUCCESS;
}
