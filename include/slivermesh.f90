!> slivermesh: Fortran 2008 interface (ISO_C_BINDING) to the C ABI of include/slivermesh.h.
!>
!> Compile this file with your program (it defines module `slivermesh`) and link libslivermesh:
!>     gfortran -c slivermesh.f90 && gfortran my_code.f90 slivermesh.o -lslivermesh
!> With CMake: find_package(SliverMesh CONFIG) gives ${SliverMesh_FORTRAN_MODULE} (this file).
!>
!> Conventions (see slivermesh.h for each function):
!>  - The handle is a type(c_ptr) from sm_create(); free it with sm_destroy().
!>  - Every fallible function returns an integer(c_int32_t) status: SM_OK (0) or SM_ERR_*;
!>    sm_last_error(m) then returns the message as a Fortran string.
!>  - Vertex ids are 0-BASED (C convention): subtract 1 from Fortran indices. They are uint32_t in
!>    C, passed here as integer(c_int32_t) (ids below 2**31).
!>  - Coordinates are real(c_double) arrays xyz(3, n); counts are integer(c_size_t).
!>  - Outputs are copied into arrays you allocate after asking for the count (sm_num_*).
!>  - Callbacks are bind(C) procedures passed with c_funloc(); user data with c_loc() or
!>    c_null_ptr. See examples/fortran/cube.f90.
!>  - Threads: sm_set_param(m, "threads", n) sets the threads of a run's parallel steps (0, the
!>    default: all cores; the mesh is the same for every count). The spacing callback is called
!>    only from the thread calling sm_refine, one call at a time, unless you declare it
!>    thread-safe with sm_set_param(m, "spacing_thread_safe", 1d0): then big batches are split
!>    across the run's threads and it is called from several at once (it must not write to
!>    shared variables without synchronisation, nor use SAVE'd state, nor OpenMP threadprivate
!>    data set only on your thread).
!>  - Functions taking a string (sm_set_param, sm_get_param, sm_write, sm_write_binary) have
!>    Fortran wrappers that add the terminating NUL; the raw bind(C) ones are *_c.
module slivermesh
  use, intrinsic :: iso_c_binding, only: c_ptr, c_funptr, c_null_ptr, c_null_char, c_char, &
                                         c_double, c_int32_t, c_int64_t, c_size_t, c_associated, &
                                         c_f_pointer
  implicit none
  private

  ! Status codes (never renumbered).
  integer(c_int32_t), parameter, public :: SM_OK = 0
  integer(c_int32_t), parameter, public :: SM_ERR_NULL = 1
  integer(c_int32_t), parameter, public :: SM_ERR_INVALID_ARGUMENT = 2
  integer(c_int32_t), parameter, public :: SM_ERR_INVALID_INPUT = 3
  integer(c_int32_t), parameter, public :: SM_ERR_SPACING = 4
  integer(c_int32_t), parameter, public :: SM_ERR_CANCELLED = 5
  integer(c_int32_t), parameter, public :: SM_ERR_BUFFER_TOO_SMALL = 6
  integer(c_int32_t), parameter, public :: SM_ERR_NOT_REFINED = 7
  integer(c_int32_t), parameter, public :: SM_ERR_IO = 8
  integer(c_int32_t), parameter, public :: SM_ERR_PANIC = 9
  integer(c_int32_t), parameter, public :: SM_ERR_POISONED = 10
  integer(c_int32_t), parameter, public :: SM_ERR_INTERNAL = 11
  integer(c_int32_t), parameter, public :: SM_ERR_BUSY = 12

  !> The last run's figures (struct sm_quality).
  type, bind(C), public :: sm_quality
    integer(c_size_t) :: n_vertices, n_tets, n_boundary_faces
    real(c_double) :: seconds_recovery, seconds_refinement, seconds_total
    real(c_double) :: max_rho, min_sigma, min_dihedral_deg, max_dihedral_deg
    integer(c_size_t) :: tets_below_deg(4)
    real(c_double) :: max_size_ratio, edge_ratio_min, edge_ratio_median, edge_ratio_max
    integer(c_size_t) :: n_acute_angles, n_bad_near_acute
    integer(c_int32_t) :: complete
  end type sm_quality

  !> One region of the last run's mesh (struct sm_region).
  type, bind(C), public :: sm_region
    integer(c_int32_t) :: attribute
    integer(c_size_t) :: tets
    real(c_double) :: volume, input_volume, relative_volume_difference
  end type sm_region

  !> Shapes of the callbacks (declare yours like these, with bind(C), and pass c_funloc(f)).
  abstract interface
    !> Target element size at (x, y, z): finite and > 0, anything else fails sm_refine.
    !> Called from one thread at a time unless "spacing_thread_safe" is 1 (see above).
    function sm_spacing_fn(x, y, z, user_data) bind(C) result(h)
      import :: c_double, c_ptr
      real(c_double), value :: x, y, z
      type(c_ptr), value :: user_data
      real(c_double) :: h
    end function sm_spacing_fn
    !> Batched: out(i) = size at xyz(:, i), i = 1..n. With "spacing_thread_safe" 1, several
    !> calls (parts of one batch) may run at the same time on the run's threads.
    subroutine sm_spacing_batch_fn(n, xyz, out, user_data) bind(C)
      import :: c_double, c_ptr, c_size_t
      integer(c_size_t), value :: n
      real(c_double), intent(in) :: xyz(3, n)
      real(c_double), intent(out) :: out(n)
      type(c_ptr), value :: user_data
    end subroutine sm_spacing_batch_fn
    !> Progress: return non-zero to cancel sm_refine.
    function sm_progress_fn(fraction, n_vertices, user_data) bind(C) result(stop)
      import :: c_double, c_size_t, c_ptr, c_int32_t
      real(c_double), value :: fraction
      integer(c_size_t), value :: n_vertices
      type(c_ptr), value :: user_data
      integer(c_int32_t) :: stop
    end function sm_progress_fn
  end interface
  public :: sm_spacing_fn, sm_spacing_batch_fn, sm_progress_fn

  interface
    function sm_create() bind(C, name="sm_create") result(m)
      import :: c_ptr
      type(c_ptr) :: m
    end function sm_create

    subroutine sm_destroy(m) bind(C, name="sm_destroy")
      import :: c_ptr
      type(c_ptr), value :: m
    end subroutine sm_destroy

    function sm_add_vertices(m, xyz, n) bind(C, name="sm_add_vertices") result(s)
      import :: c_ptr, c_double, c_size_t, c_int32_t
      type(c_ptr), value :: m
      real(c_double), intent(in) :: xyz(*)
      integer(c_size_t), value :: n
      integer(c_int32_t) :: s
    end function sm_add_vertices

    function sm_add_facet(m, ids, n, marker) bind(C, name="sm_add_facet") result(s)
      import :: c_ptr, c_size_t, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t), intent(in) :: ids(*)
      integer(c_size_t), value :: n
      integer(c_int32_t), value :: marker
      integer(c_int32_t) :: s
    end function sm_add_facet

    function sm_add_facet_hole(m, ids, n) bind(C, name="sm_add_facet_hole") result(s)
      import :: c_ptr, c_size_t, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t), intent(in) :: ids(*)
      integer(c_size_t), value :: n
      integer(c_int32_t) :: s
    end function sm_add_facet_hole

    function sm_add_hole(m, x, y, z) bind(C, name="sm_add_hole") result(s)
      import :: c_ptr, c_double, c_int32_t
      type(c_ptr), value :: m
      real(c_double), value :: x, y, z
      integer(c_int32_t) :: s
    end function sm_add_hole

    function sm_add_region(m, x, y, z, attribute, max_size) bind(C, name="sm_add_region") &
        result(s)
      import :: c_ptr, c_double, c_int32_t
      type(c_ptr), value :: m
      real(c_double), value :: x, y, z
      integer(c_int32_t), value :: attribute
      real(c_double), value :: max_size
      integer(c_int32_t) :: s
    end function sm_add_region

    function sm_set_spacing_cb(m, f, user_data) bind(C, name="sm_set_spacing_cb") result(s)
      import :: c_ptr, c_funptr, c_int32_t
      type(c_ptr), value :: m
      type(c_funptr), value :: f
      type(c_ptr), value :: user_data
      integer(c_int32_t) :: s
    end function sm_set_spacing_cb

    function sm_set_spacing_batch_cb(m, f, user_data) bind(C, name="sm_set_spacing_batch_cb") &
        result(s)
      import :: c_ptr, c_funptr, c_int32_t
      type(c_ptr), value :: m
      type(c_funptr), value :: f
      type(c_ptr), value :: user_data
      integer(c_int32_t) :: s
    end function sm_set_spacing_batch_cb

    function sm_set_spacing_const(m, h) bind(C, name="sm_set_spacing_const") result(s)
      import :: c_ptr, c_double, c_int32_t
      type(c_ptr), value :: m
      real(c_double), value :: h
      integer(c_int32_t) :: s
    end function sm_set_spacing_const

    !> Spacing from a size field on a background tet mesh: xyz(3 * n_vertices), tets(4 * n_tets)
    !> (0-based vertex ids), values(n_vertices) > 0; linear in the tets, nearest point outside.
    function sm_set_spacing_mesh(m, xyz, n_vertices, tets, n_tets, values) &
        bind(C, name="sm_set_spacing_mesh") result(s)
      import :: c_ptr, c_double, c_size_t, c_int32_t
      type(c_ptr), value :: m
      real(c_double), intent(in) :: xyz(*)
      integer(c_size_t), value :: n_vertices
      integer(c_int32_t), intent(in) :: tets(*)
      integer(c_size_t), value :: n_tets
      real(c_double), intent(in) :: values(*)
      integer(c_int32_t) :: s
    end function sm_set_spacing_mesh

    !> An existing mesh whose slivers sm_refine removes (keep mode): xyz(3, n_vertices),
    !> tets(4, n_tets) 0-based with regions(n_tets), tris(3, n_tris) with markers(n_tris).
    function sm_set_existing_mesh(m, xyz, n_vertices, tets, regions, n_tets, tris, markers, &
        n_tris) bind(C, name="sm_set_existing_mesh") result(s)
      import :: c_ptr, c_double, c_size_t, c_int32_t
      type(c_ptr), value :: m
      real(c_double), intent(in) :: xyz(*)
      integer(c_size_t), value :: n_vertices
      integer(c_int32_t), intent(in) :: tets(*)
      integer(c_int32_t), intent(in) :: regions(*)
      integer(c_size_t), value :: n_tets
      integer(c_int32_t), intent(in) :: tris(*)
      integer(c_int32_t), intent(in) :: markers(*)
      integer(c_size_t), value :: n_tris
      integer(c_int32_t) :: s
    end function sm_set_existing_mesh

    !> Spacing at most h in the region of attribute id (h > 0; an id the input lacks fails sm_refine).
    function sm_set_region_size(m, id, h) bind(C, name="sm_set_region_size") result(s)
      import :: c_ptr, c_double, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t), value :: id
      real(c_double), value :: h
      integer(c_int32_t) :: s
    end function sm_set_region_size

    !> Spacing at most h near the input facets of marker id, growing away as
    !> h + 0.5 * (distance - h) (h > 0; an id no input facet has fails sm_refine).
    function sm_set_marker_size(m, id, h) bind(C, name="sm_set_marker_size") result(s)
      import :: c_ptr, c_double, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t), value :: id
      real(c_double), value :: h
      integer(c_int32_t) :: s
    end function sm_set_marker_size

    function sm_set_param_c(m, name, value) bind(C, name="sm_set_param") result(s)
      import :: c_ptr, c_char, c_double, c_int32_t
      type(c_ptr), value :: m
      character(kind=c_char), intent(in) :: name(*)
      real(c_double), value :: value
      integer(c_int32_t) :: s
    end function sm_set_param_c

    function sm_get_param_c(m, name, value) bind(C, name="sm_get_param") result(s)
      import :: c_ptr, c_char, c_double, c_int32_t
      type(c_ptr), value :: m
      character(kind=c_char), intent(in) :: name(*)
      real(c_double), intent(out) :: value
      integer(c_int32_t) :: s
    end function sm_get_param_c

    function sm_set_progress_cb(m, f, user_data) bind(C, name="sm_set_progress_cb") result(s)
      import :: c_ptr, c_funptr, c_int32_t
      type(c_ptr), value :: m
      type(c_funptr), value :: f
      type(c_ptr), value :: user_data
      integer(c_int32_t) :: s
    end function sm_set_progress_cb

    function sm_refine(m) bind(C, name="sm_refine") result(s)
      import :: c_ptr, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t) :: s
    end function sm_refine

    !> Distributed meshing (a library built with the cargo feature mpi only): every rank of
    !> the communicator comm (the integer handle, e.g. MPI_COMM_WORLD or comm%MPI_VAL) meshes
    !> its part; see sm_refine_mpi in slivermesh.h.
    function sm_refine_mpi(m, comm) bind(C, name="sm_refine_mpi") result(s)
      import :: c_ptr, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t), value :: comm
      integer(c_int32_t) :: s
    end function sm_refine_mpi

    !> Global id of each of this rank's vertices after sm_refine_mpi (ids(n_vertices)).
    function sm_get_global_vertex_ids(m, ids, capacity) &
        bind(C, name="sm_get_global_vertex_ids") result(s)
      import :: c_ptr, c_int64_t, c_size_t, c_int32_t
      type(c_ptr), value :: m
      integer(c_int64_t), intent(out) :: ids(*)
      integer(c_size_t), value :: capacity
      integer(c_int32_t) :: s
    end function sm_get_global_vertex_ids

    !> Global vertex and tet counts and the global id of this rank's first tet.
    function sm_global_counts(m, n_vertices, n_tets, first_tet) &
        bind(C, name="sm_global_counts") result(s)
      import :: c_ptr, c_int64_t, c_int32_t
      type(c_ptr), value :: m
      integer(c_int64_t), intent(out) :: n_vertices, n_tets, first_tet
      integer(c_int32_t) :: s
    end function sm_global_counts

    function sm_num_vertices(m) bind(C, name="sm_num_vertices") result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: m
      integer(c_size_t) :: n
    end function sm_num_vertices

    function sm_num_tets(m) bind(C, name="sm_num_tets") result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: m
      integer(c_size_t) :: n
    end function sm_num_tets

    function sm_num_boundary_faces(m) bind(C, name="sm_num_boundary_faces") result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: m
      integer(c_size_t) :: n
    end function sm_num_boundary_faces

    !> xyz(3, capacity)
    function sm_get_vertices(m, xyz, capacity) bind(C, name="sm_get_vertices") result(s)
      import :: c_ptr, c_double, c_size_t, c_int32_t
      type(c_ptr), value :: m
      real(c_double), intent(inout) :: xyz(*)
      integer(c_size_t), value :: capacity
      integer(c_int32_t) :: s
    end function sm_get_vertices

    !> With sm_set_param(m, "order", 2d0): vertices, then one node per edge.
    function sm_num_nodes(m) bind(C, name="sm_num_nodes") result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: m
      integer(c_size_t) :: n
    end function sm_num_nodes

    !> xyz(3, capacity): the vertices, then the mid-edge nodes of ten-node tets.
    function sm_get_nodes(m, xyz, capacity) bind(C, name="sm_get_nodes") result(s)
      import :: c_ptr, c_double, c_size_t, c_int32_t
      type(c_ptr), value :: m
      real(c_double), intent(inout) :: xyz(*)
      integer(c_size_t), value :: capacity
      integer(c_int32_t) :: s
    end function sm_get_nodes

    !> tets10(10, capacity) 0-based node ids: corners, then edges 01 12 02 03 13 23
    !> (VTK_QUADRATIC_TETRA / Abaqus C3D10 order). Needs "order" 2.
    function sm_get_tets10(m, tets10, capacity) bind(C, name="sm_get_tets10") result(s)
      import :: c_ptr, c_size_t, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t), intent(inout) :: tets10(*)
      integer(c_size_t), value :: capacity
      integer(c_int32_t) :: s
    end function sm_get_tets10

    !> tets(4, capacity) 0-based ids; regions(capacity) may be omitted (NULL). Regions: the
    !> seeds' attributes, else 1, 2, ... per enclosed volume (0 for one piece), see slivermesh.h.
    function sm_get_tets(m, tets, regions, capacity) bind(C, name="sm_get_tets") result(s)
      import :: c_ptr, c_size_t, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t), intent(inout) :: tets(*)
      integer(c_int32_t), intent(inout), optional :: regions(*)
      integer(c_size_t), value :: capacity
      integer(c_int32_t) :: s
    end function sm_get_tets

    !> tris(3, capacity) 0-based ids; markers(capacity) may be omitted (NULL). An interface
    !> between two regions is listed once.
    function sm_get_boundary_faces(m, tris, markers, capacity) &
        bind(C, name="sm_get_boundary_faces") result(s)
      import :: c_ptr, c_size_t, c_int32_t
      type(c_ptr), value :: m
      integer(c_int32_t), intent(inout) :: tris(*)
      integer(c_int32_t), intent(inout), optional :: markers(*)
      integer(c_size_t), value :: capacity
      integer(c_int32_t) :: s
    end function sm_get_boundary_faces

    function sm_get_quality(m, out) bind(C, name="sm_get_quality") result(s)
      import :: c_ptr, c_int32_t, sm_quality
      type(c_ptr), value :: m
      type(sm_quality), intent(inout) :: out
      integer(c_int32_t) :: s
    end function sm_get_quality

    function sm_num_regions(m) bind(C, name="sm_num_regions") result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: m
      integer(c_size_t) :: n
    end function sm_num_regions

    !> regions(capacity), sorted by attribute; the two areas may be omitted (NULL).
    function sm_get_regions(m, regions, capacity, interface_area, input_interface_area) &
        bind(C, name="sm_get_regions") result(s)
      import :: c_ptr, c_size_t, c_double, c_int32_t, sm_region
      type(c_ptr), value :: m
      type(sm_region), intent(inout) :: regions(*)
      integer(c_size_t), value :: capacity
      real(c_double), intent(inout), optional :: interface_area, input_interface_area
      integer(c_int32_t) :: s
    end function sm_get_regions

    function sm_write_c(m, path) bind(C, name="sm_write") result(s)
      import :: c_ptr, c_char, c_int32_t
      type(c_ptr), value :: m
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int32_t) :: s
    end function sm_write_c

    function sm_write_binary_c(m, path) bind(C, name="sm_write_binary") result(s)
      import :: c_ptr, c_char, c_int32_t
      type(c_ptr), value :: m
      character(kind=c_char), intent(in) :: path(*)
      integer(c_int32_t) :: s
    end function sm_write_binary_c

    function sm_last_error_c(m) bind(C, name="sm_last_error") result(p)
      import :: c_ptr
      type(c_ptr), value :: m
      type(c_ptr) :: p
    end function sm_last_error_c

    function sm_stop_reason_c(m) bind(C, name="sm_stop_reason") result(p)
      import :: c_ptr
      type(c_ptr), value :: m
      type(c_ptr) :: p
    end function sm_stop_reason_c

    function sm_status_str_c(s) bind(C, name="sm_status_str") result(p)
      import :: c_ptr, c_int32_t
      integer(c_int32_t), value :: s
      type(c_ptr) :: p
    end function sm_status_str_c

    function sm_version_c() bind(C, name="sm_version") result(p)
      import :: c_ptr
      type(c_ptr) :: p
    end function sm_version_c

    function c_strlen(p) bind(C, name="strlen") result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: p
      integer(c_size_t) :: n
    end function c_strlen
  end interface

  public :: sm_create, sm_destroy, sm_add_vertices, sm_add_facet, sm_add_facet_hole, &
            sm_add_hole, sm_add_region, sm_set_spacing_cb, sm_set_spacing_batch_cb, &
            sm_set_spacing_const, sm_set_spacing_mesh, sm_set_region_size, sm_set_marker_size, &
            sm_set_existing_mesh, &
            sm_set_param_c, sm_get_param_c, sm_set_progress_cb, &
            sm_refine, sm_refine_mpi, sm_get_global_vertex_ids, sm_global_counts, &
            sm_num_vertices, sm_num_tets, sm_num_boundary_faces, sm_get_vertices, &
            sm_get_tets, sm_get_boundary_faces, sm_get_quality, sm_num_nodes, sm_get_nodes, &
            sm_get_tets10, sm_num_regions, sm_get_regions, &
            sm_write_c, sm_write_binary_c, sm_last_error_c, &
            sm_stop_reason_c, sm_status_str_c, sm_version_c
  public :: sm_set_param, sm_get_param, sm_write, sm_write_binary, sm_last_error, &
            sm_stop_reason, sm_status_str, sm_version

contains

  !> A Fortran string as a NUL-terminated C string.
  pure function c_string(s) result(c)
    character(len=*), intent(in) :: s
    character(kind=c_char, len=len_trim(s) + 1) :: c
    c = trim(s) // c_null_char
  end function c_string

  !> A copy of the NUL-terminated C string at p ("" for a NULL pointer).
  function f_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(len=:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: i, n
    if (.not. c_associated(p)) then
      s = ""
      return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate (character(len=n) :: s)
    do i = 1, n
      s(i:i) = chars(i)
    end do
  end function f_string

  !> sm_set_param with a Fortran string name ("rho0", "sigma0", "seed", "surface_mode",
  !> "threads", "spacing_thread_safe", ...; every name and range: sm_set_param in slivermesh.h).
  function sm_set_param(m, name, value) result(s)
    type(c_ptr), intent(in) :: m
    character(len=*), intent(in) :: name
    real(c_double), intent(in) :: value
    integer(c_int32_t) :: s
    s = sm_set_param_c(m, c_string(name), value)
  end function sm_set_param

  !> sm_get_param with a Fortran string name.
  function sm_get_param(m, name, value) result(s)
    type(c_ptr), intent(in) :: m
    character(len=*), intent(in) :: name
    real(c_double), intent(out) :: value
    integer(c_int32_t) :: s
    s = sm_get_param_c(m, c_string(name), value)
  end function sm_get_param

  !> sm_write with a Fortran string path (format by extension: .vtu, .mesh, .msh, .node).
  function sm_write(m, path) result(s)
    type(c_ptr), intent(in) :: m
    character(len=*), intent(in) :: path
    integer(c_int32_t) :: s
    s = sm_write_c(m, c_string(path))
  end function sm_write

  !> sm_write_binary with a Fortran string path (.msh: gmsh 4.1 binary, .vtu: binary appended
  !> arrays; other formats as sm_write).
  function sm_write_binary(m, path) result(s)
    type(c_ptr), intent(in) :: m
    character(len=*), intent(in) :: path
    integer(c_int32_t) :: s
    s = sm_write_binary_c(m, c_string(path))
  end function sm_write_binary

  !> The message of the last fallible call on m ("" after a success).
  function sm_last_error(m) result(msg)
    type(c_ptr), intent(in) :: m
    character(len=:), allocatable :: msg
    msg = f_string(sm_last_error_c(m))
  end function sm_last_error

  !> Why the last sm_refine stopped early ("" if it completed).
  function sm_stop_reason(m) result(msg)
    type(c_ptr), intent(in) :: m
    character(len=:), allocatable :: msg
    msg = f_string(sm_stop_reason_c(m))
  end function sm_stop_reason

  !> A description of a status code.
  function sm_status_str(s) result(msg)
    integer(c_int32_t), intent(in) :: s
    character(len=:), allocatable :: msg
    msg = f_string(sm_status_str_c(s))
  end function sm_status_str

  !> The library version.
  function sm_version() result(v)
    character(len=:), allocatable :: v
    v = f_string(sm_version_c())
  end function sm_version

end module slivermesh
