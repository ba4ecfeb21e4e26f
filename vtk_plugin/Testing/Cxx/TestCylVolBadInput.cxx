// Every bad input through vtkCylVolMapper: an unsupported cell type, missing scalars,
// multi-component scalars without a chosen component, an empty grid, scalars of the wrong
// length, NaN coordinates, an input that is no vtkUnstructuredGrid (given as data or from a
// pipeline, where the error names the type given), a negative, NaN or infinite maximum
// error... Each must raise a
// vtkErrorMacro naming the problem (caught by an error observer), draw nothing (the window
// stays at its background) and not crash; a good input drawn afterwards by the same mapper
// must still work.
#include "vtkCylVolMapper.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkExecutive.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkSphereSource.h"
#include "vtkTestErrorObserver.h"
#include "vtkTrivialProducer.h"
#include "vtkVolume.h"

#include "CylVolTestUtilities.h"

#include <cmath>
#include <limits>

namespace
{
// A 2x2x2 block of hexahedra (27 points) with a point scalar "s" (1 component).
vtkSmartPointer<vtkUnstructuredGrid> Block()
{
  auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
  vtkNew<vtkPoints> points;
  vtkNew<vtkFloatArray> s;
  s->SetName("s");
  for (int k = 0; k < 3; ++k)
  {
    for (int j = 0; j < 3; ++j)
    {
      for (int i = 0; i < 3; ++i)
      {
        points->InsertNextPoint(i, j, k);
        s->InsertNextValue(static_cast<float>(i + j + k));
      }
    }
  }
  grid->SetPoints(points);
  auto id = [](int i, int j, int k) { return static_cast<vtkIdType>(i + 3 * (j + 3 * k)); };
  for (int k = 0; k < 2; ++k)
  {
    for (int j = 0; j < 2; ++j)
    {
      for (int i = 0; i < 2; ++i)
      {
        vtkIdType c[8] = { id(i, j, k), id(i + 1, j, k), id(i + 1, j + 1, k), id(i, j + 1, k),
          id(i, j, k + 1), id(i + 1, j, k + 1), id(i + 1, j + 1, k + 1), id(i, j + 1, k + 1) };
        grid->InsertNextCell(VTK_HEXAHEDRON, 8, c);
      }
    }
  }
  grid->GetPointData()->SetScalars(s);
  return grid;
}

struct Scene
{
  vtkNew<vtkCylVolMapper> Mapper;
  vtkNew<vtkVolume> Volume;
  vtkNew<vtkRenderer> Ren;
  vtkSmartPointer<vtkRenderWindow> Win;
  vtkNew<vtkTest::ErrorObserver> Errors;
  // The executive's own complaints about an input of the wrong type (it names the type too,
  // but they are not the mapper's report).
  vtkNew<vtkTest::ErrorObserver> PipelineErrors;

  Scene()
  {
    cylvoltest::Dataset d;
    d.Range[0] = 0.0;
    d.Range[1] = 6.0;
    d.Diagonal = 1.0;
    this->Volume->SetMapper(this->Mapper);
    this->Volume->SetProperty(cylvoltest::MakeProperty(d, false));
    this->Ren->AddVolume(this->Volume);
    this->Win = cylvoltest::MakeWindow(100, 100, this->Ren);
    this->Mapper->AddObserver(vtkCommand::ErrorEvent, this->Errors);
    this->Mapper->GetExecutive()->AddObserver(vtkCommand::ErrorEvent, this->PipelineErrors);
  }

  // Renders `grid`; returns true when the expectation holds: an error containing `needle`
  // and a background-only image when `needle` is non-empty; no error and some volume in
  // the image when it is empty.
  bool Check(const char* label, vtkDataSet* grid, const std::string& needle)
  {
    this->Mapper->RemoveAllInputConnections(0);
    this->Errors->Clear();
    this->Mapper->SetInputData(grid);
    return this->Draw(label, needle);
  }

  // The same with the output of `source` connected to the mapper.
  bool CheckConnection(const char* label, vtkAlgorithm* source, const std::string& needle)
  {
    this->Mapper->RemoveAllInputConnections(0);
    this->Errors->Clear();
    this->Mapper->SetInputConnection(source->GetOutputPort());
    const bool ok = this->Draw(label, needle);
    this->Mapper->RemoveAllInputConnections(0);
    return ok;
  }

  bool Draw(const char* label, const std::string& needle)
  {
    this->Ren->ResetCamera(-0.5, 2.5, -0.5, 2.5, -0.5, 2.5);
    this->Win->Render();
    auto image = cylvoltest::Grab(this->Win);
    const unsigned char* p =
      static_cast<unsigned char*>(image->GetPointData()->GetScalars()->GetVoidPointer(0));
    vtkIdType lit = 0;
    for (vtkIdType i = 0; i < 3 * image->GetNumberOfPoints(); ++i)
    {
      lit += p[i] ? 1 : 0;
    }
    const bool error = this->Errors->GetError();
    std::string message = error ? this->Errors->GetErrorMessage() : std::string();
    // Printed without VTK's "ERROR: " prefix, which CTest would take for a failure.
    for (size_t at = message.find("ERROR: "); at != std::string::npos; at = message.find("ERROR: "))
    {
      message.replace(at, 7, "error: ");
    }
    bool ok;
    if (needle.empty())
    {
      ok = !error && lit > 0;
    }
    else
    {
      ok = error && message.find(needle) != std::string::npos && lit == 0;
    }
    std::cout << (ok ? "ok   " : "FAIL ") << label << ": " << (error ? "error" : "no error")
              << ", " << lit << " lit channel values"
              << (message.empty() ? "" : "\n       message: ") << message << "\n";
    return ok;
  }
};
} // namespace

int TestCylVolBadInput(int, char*[])
{
  Scene scene;
  bool ok = true;

  ok &= scene.Check("good block", Block(), "");

  {
    auto grid = Block();
    vtkIdType quad[4] = { 0, 1, 4, 3 };
    grid->InsertNextCell(VTK_QUAD, 4, quad);
    ok &= scene.Check("quad cell", grid, "Unsupported cell type 9 (vtkQuad)");
  }
  {
    auto grid = Block();
    vtkIdType q[20];
    for (int i = 0; i < 20; ++i)
    {
      q[i] = i;
    }
    grid->InsertNextCell(VTK_QUADRATIC_HEXAHEDRON, 20, q);
    ok &= scene.Check("quadratic hexahedron", grid, "Unsupported cell type 25");
  }
  {
    auto grid = Block();
    grid->GetPointData()->Initialize();
    ok &= scene.Check("no scalars", grid, "No scalars");
  }
  {
    auto grid = Block();
    vtkNew<vtkDoubleArray> v;
    v->SetName("v");
    v->SetNumberOfComponents(3);
    v->SetNumberOfTuples(grid->GetNumberOfPoints());
    for (vtkIdType i = 0; i < grid->GetNumberOfPoints(); ++i)
    {
      v->SetTuple3(i, 1.0 * i, 2.0, 3.0);
    }
    grid->GetPointData()->SetScalars(v);
    ok &= scene.Check("3 components, none chosen", grid, "has 3 components and no valid component");
    scene.Mapper->SetScalarComponent(5);
    ok &= scene.Check("3 components, component 5", grid, "has 3 components and no valid component");
    scene.Mapper->SetScalarComponent(0);
    ok &= scene.Check("3 components, component 0", grid, "");
    scene.Mapper->SetScalarComponent(-1);
  }
  {
    auto grid = vtkSmartPointer<vtkUnstructuredGrid>::New();
    vtkNew<vtkPoints> points;
    grid->SetPoints(points);
    grid->Allocate(1);
    ok &= scene.Check("empty grid", grid, "is empty");
  }
  {
    auto grid = Block();
    grid->GetPoints()->SetPoint(13, std::numeric_limits<double>::quiet_NaN(), 1.0, 1.0);
    ok &= scene.Check("NaN coordinate", grid, "cylvol rejected the grid");
  }
  {
    auto grid = Block();
    grid->GetPointData()->GetScalars()->SetComponent(4, 0, std::numeric_limits<double>::infinity());
    ok &= scene.Check("infinite scalar", grid, "cylvol rejected");
  }
  {
    vtkNew<vtkImageData> image;
    image->SetDimensions(3, 3, 3);
    image->AllocateScalars(VTK_FLOAT, 1);
    ok &= scene.Check("image data input", image, "requires vtkUnstructuredGridBase");
  }
  {
    vtkNew<vtkImageData> image;
    image->SetDimensions(3, 3, 3);
    image->AllocateScalars(VTK_FLOAT, 1);
    vtkNew<vtkTrivialProducer> producer;
    producer->SetOutput(image);
    ok &= scene.CheckConnection("image data from a pipeline", producer,
      "The input is a vtkImageData, but vtkCylVolMapper needs a vtkUnstructuredGrid");
    vtkNew<vtkSphereSource> sphere;
    ok &= scene.CheckConnection("polygons from a pipeline", sphere,
      "The input is a vtkPolyData, but vtkCylVolMapper needs a vtkUnstructuredGrid");
  }
  {
    auto grid = Block();
    scene.Mapper->SetScalarModeToUsePointFieldData();
    scene.Mapper->SelectScalarArray("no-such-array");
    ok &= scene.Check("unknown array name", grid, "No scalars");
    scene.Mapper->SetScalarModeToDefault();
  }
  // A maximum error that is negative, NaN or infinite: cylvol refuses the render.
  for (const double bad :
    { -1.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity() })
  {
    scene.Mapper->SetMaximumError(bad);
    ok &= scene.Check("maximum error", Block(), "params->max_error");
  }
  scene.Mapper->SetMaximumError(0.0);
  // The mapper is still usable after all that.
  ok &= scene.Check("good block again", Block(), "");
  return ok ? EXIT_SUCCESS : EXIT_FAILURE;
}
