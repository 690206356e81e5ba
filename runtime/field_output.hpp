#pragma once
// Field output for ParaView (DESIGN.md "Inputs and outputs", SCENE.md
// "Outputs"): DIR/fields.h5, written collectively by every rank through
// parallel HDF5 (MPI-IO), indexed by DIR/fields.xdmf (XDMF 3).
//
// Layout of fields.h5 (n = nodes, e = elements, summed over ranks):
//   /mesh/<k>/coordinates   n x 3 float64   reference coordinates X, m
//   /mesh/<k>/topology      e x 4 or e x 10 int64, node rows of /mesh/<k>
//                           (TET10 in XDMF/VTK order: mid-edge nodes on edges
//                           4:(0,1) 5:(1,2) 6:(0,2) 7:(0,3) 8:(1,3) 9:(2,3))
//   /step_<NNNNNN>/         one group per frame, attributes time (float64, s),
//                           step (int32) and mesh (int32, the k it refers to)
//       displacement        n x 3 float64, m
//       velocity            n x 3 float64, m/s
//       stress              e x 6 float64, Cauchy stress in XDMF Tensor6 order
//                           xx xy xz yy yz zz, Pa
//       von_mises           e float64, Pa
//       body                e int32
//       fragment            e int32 (only when fracture is on)
//       damage              e float64 (only when given)
// With shells (v control vertices, s triangles; FieldFrame::shell_*):
//   /mesh/<k>/shell_coordinates  v x 3 float64, the reference limit surface at
//                           the control vertices, m
//   /mesh/<k>/shell_topology  s x 3 int64, rows of shell_coordinates
//   /mesh/<k>/shell_body    s int32, the body of each shell triangle
//   /step_<NNNNNN>/shell_displacement, shell_velocity  v x 3 float64, of the
//                           limit surface at the control vertices, m and m/s
//   /step_<NNNNNN>/shell_membrane_force, shell_bending_moment  s x 6 float64,
//                           the triangles' stress resultants (ShellResultants)
//                           in Tensor6 order xx xy xz yy yz zz, N/m and N m/m
// and each frame is a spatial collection of two grids, "solids" (the
// tetrahedra, left out when there are none) and "shells" (the mid-surface:
// the control triangles with their corners on the limit surface).
// A mesh group k = 0, 1, ... is written for the first frame and again for
// every frame whose mesh topology changed (fracture splits nodes).
//
// In ParaView (checked with 5.11: Xdmf3ReaderS, Xdmf3ReaderT and the legacy
// XDMF Reader) the frames are time steps, TET10 cells are quadratic
// tetrahedra and "Warp By Vector" on displacement shows the deformed shape.
// The legacy reader expands stress to the full 3x3 tensor; the Xdmf3 readers
// pass its 6 components through in file order (xx xy xz yy yz zz), which the
// ParaView GUI labels in VTK's order (XX YY ZZ XY YZ XZ).
#include <mpi.h>

#include <array>
#include <filesystem>
#include <memory>
#include <span>
#include <vector>

#include "kernels/types.hpp"
#include "mesh/mesh.hpp"

namespace shatter {

struct ShellFrame;

/// Fields of one output frame for the items this rank writes (all of them on
/// 1 rank). Row i of a per-node array belongs to node i of the Mesh passed
/// with it, row e of a per-element array to its element e.
struct FieldFrame {
  int step = 0;       ///< time step number; names the group /step_<NNNNNN>
  double time = 0.0;  ///< s
  std::span<const Vec3> displacement;  ///< [n] per node, x - X, m
  std::span<const Vec3> velocity;      ///< [n] per node, m/s
  /// [e*6 + c] per element, Cauchy stress in Voigt order c = xx yy zz yz xz xy, Pa.
  std::span<const double> stress;
  std::span<const double> von_mises;  ///< [e] per element, Pa
  std::span<const int> body;          ///< [e] per element, body index
  /// [e] per element, fragment id; empty when fracture is off (then not written).
  std::span<const int> fragment;
  /// [e] per element, damage in [0, 1]; optional (empty = not written).
  std::span<const double> damage;
  /// The shells' mid-surface (ShellFrame); null without shells.
  const ShellFrame* shells = nullptr;
};

/// The shells' mid-surface in one frame: the rows this rank writes (all of
/// them on one rank), s triangles and v control vertices, after the rows of
/// the lower ranks; the whole is body after body.
struct ShellFrame {
  std::vector<std::array<Index, 3>> triangles;  ///< [s] control triangles, in rows of all ranks' shell vertices
  std::vector<int> body;                         ///< [s] body index
  /// [v] the limit surface at the control vertices: reference point (m),
  /// displacement (m) and velocity (m/s)
  std::vector<Vec3> reference, displacement, velocity;
  /// [s*6 + c] membrane force (N/m) and bending moment (N m/m) of each
  /// triangle, Voigt order c = xx yy zz yz xz xy
  std::vector<double> membrane_force, bending_moment;
};

/// Writes fields.h5 and its XDMF index fields.xdmf into one directory.
///
/// Every rank of `comm` calls the constructor, write() and the destructor
/// collectively. Each rank writes the rows of the nodes and elements it owns,
/// placed after the rows of the lower ranks (offsets from MPI_Exscan of the
/// counts), with collective MPI-IO transfers. Assumption: the Mesh a rank
/// passes holds exactly its output rows, and its connectivity `conn` is
/// already in output numbering, i.e. indexes the rows of all ranks in rank
/// order (on one rank: the local ids). Only rank 0 writes fields.xdmf.
class FieldWriter {
 public:
  /// Creates `dir` if needed and `dir`/fields.h5 (truncating it) with
  /// H5Pset_fapl_mpio on `comm`, and an fields.xdmf without frames.
  /// Throws shatter::Error naming the path when either cannot be created.
  FieldWriter(const std::filesystem::path& dir, MPI_Comm comm);
  /// Closes fields.h5 (collective).
  ~FieldWriter();
  FieldWriter(const FieldWriter&) = delete;
  FieldWriter& operator=(const FieldWriter&) = delete;

  /// Writes one frame (collective). The mesh geometry and topology (reference
  /// coordinates + connectivity) are written for the first frame and again
  /// only when mesh.revision, the order or the global counts change (fracture
  /// splits nodes). fields.xdmf is rewritten (atomically) after every frame,
  /// so it always describes the frames written so far.
  /// Throws shatter::Error when a span's size does not match the mesh, the
  /// step was already written, or HDF5 fails.
  void write(const Mesh& mesh, const FieldFrame& frame);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace shatter
