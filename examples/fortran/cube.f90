!> Meshes the unit cube from Fortran with a spacing given by a Fortran function (fine near the
!> origin corner, coarse away from it), writes cube_f.vtu and prints the quality.
!>
!>     ./cube_f [output.vtu]
!>
!> Build against an installed slivermesh (scripts/install.sh PREFIX):
!>     cmake -S examples/fortran -B build/example-fortran -DCMAKE_PREFIX_PATH=PREFIX
!>     cmake --build build/example-fortran
!> or by hand:
!>     gfortran PREFIX/include/slivermesh.f90 cube.f90 -LPREFIX/lib -lslivermesh \
!>              -Wl,-rpath,PREFIX/lib -o cube_f

!> The callbacks: bind(C) module procedures, so c_funloc() can hand them to the library.
module cube_callbacks
  use, intrinsic :: iso_c_binding, only: c_double, c_ptr, c_size_t, c_int32_t, c_f_pointer
  implicit none

  !> User data for the spacing: reached through the void* the library passes back.
  type :: grading
    real(c_double) :: h_min = 0.05_c_double, h_max = 0.3_c_double
  end type grading

contains

  function cube_spacing(x, y, z, user_data) bind(C) result(h)
    real(c_double), value :: x, y, z
    type(c_ptr), value :: user_data
    real(c_double) :: h
    type(grading), pointer :: g
    call c_f_pointer(user_data, g)
    ! Grows with the distance to the origin corner.
    h = g%h_min + (g%h_max - g%h_min) * min(1.0_c_double, sqrt(x * x + y * y + z * z))
  end function cube_spacing

  function cube_progress(fraction, n_vertices, user_data) bind(C) result(stop)
    real(c_double), value :: fraction
    integer(c_size_t), value :: n_vertices
    type(c_ptr), value :: user_data
    integer(c_int32_t) :: stop
    integer(c_size_t), pointer :: next_count
    ! Report each time the vertex count doubles (fraction: share of the vertex budget used).
    call c_f_pointer(user_data, next_count)
    if (n_vertices >= next_count) then
      print '(2x, i0, a, f8.4, a)', n_vertices, ' vertices (', 100 * fraction, &
        ' % of the vertex budget)'
      next_count = 2 * n_vertices
    end if
    stop = 0  ! non-zero would cancel sm_refine
  end function cube_progress

end module cube_callbacks

program cube
  use, intrinsic :: iso_c_binding
  use slivermesh
  use cube_callbacks
  implicit none

  type(c_ptr) :: m
  type(grading), target :: g
  integer(c_size_t), target :: next_count = 0
  type(sm_quality) :: q
  real(c_double) :: xyz(3, 8)
  ! Vertex ids are 0-based (C convention).
  integer(c_int32_t), parameter :: faces(4, 6) = reshape([ &
    0, 2, 3, 1,  4, 5, 7, 6,  0, 1, 5, 4,  2, 6, 7, 3,  0, 4, 6, 2,  1, 3, 7, 5], [4, 6])
  integer(c_int32_t), allocatable :: tets(:, :), regions(:)
  real(c_double), allocatable :: vertices(:, :)
  character(len=256) :: out
  integer :: i, k
  real(c_double) :: volume

  out = 'cube_f.vtu'
  if (command_argument_count() > 0) call get_command_argument(1, out)

  do i = 0, 7
    xyz(:, i + 1) = [real(iand(i, 1), c_double), real(iand(ishft(i, -1), 1), c_double), &
                     real(iand(ishft(i, -2), 1), c_double)]
  end do

  m = sm_create()
  print '(2a)', 'slivermesh ', sm_version()
  call check(sm_add_vertices(m, xyz, 8_c_size_t), 'sm_add_vertices')
  do k = 1, 6
    call check(sm_add_facet(m, faces(:, k), 4_c_size_t, int(k, c_int32_t)), 'sm_add_facet')
  end do
  call check(sm_add_region(m, 0.5d0, 0.5d0, 0.5d0, 1_c_int32_t, 0d0), 'sm_add_region')
  call check(sm_set_spacing_cb(m, c_funloc(cube_spacing), c_loc(g)), 'sm_set_spacing_cb')
  call check(sm_set_progress_cb(m, c_funloc(cube_progress), c_loc(next_count)), &
             'sm_set_progress_cb')
  call check(sm_set_param(m, 'rho0', 2.0_c_double), 'sm_set_param')
  call check(sm_refine(m), 'sm_refine')
  call check(sm_write(m, trim(out)), 'sm_write')
  call check(sm_get_quality(m, q), 'sm_get_quality')

  ! Copy the mesh out: ask for the counts, allocate, copy.
  allocate (vertices(3, sm_num_vertices(m)), tets(4, sm_num_tets(m)), regions(sm_num_tets(m)))
  call check(sm_get_vertices(m, vertices, size(vertices, 2, c_size_t)), 'sm_get_vertices')
  call check(sm_get_tets(m, tets, regions, size(tets, 2, c_size_t)), 'sm_get_tets')
  volume = 0
  do k = 1, size(tets, 2)
    volume = volume + tet_volume(vertices(:, tets(:, k) + 1))  ! +1: 0-based ids
  end do

  print '(2a)', 'wrote ', trim(out)
  print '(a, i0, a, i0, a, i0, a, f14.12)', 'vertices ', q%n_vertices, ', tets ', q%n_tets, &
    ', boundary triangles ', q%n_boundary_faces, ', volume ', volume
  print '(a, f6.3, a, f7.4, a, f6.2, a, f6.2, a)', 'max radius-edge ', q%max_rho, &
    ', min sigma ', q%min_sigma, ', dihedral angles [', q%min_dihedral_deg, ', ', &
    q%max_dihedral_deg, '] deg'
  if (q%complete /= 0) then
    print '(a)', 'complete: yes'
  else
    print '(2a)', 'complete: no: ', sm_stop_reason(m)
  end if
  call sm_destroy(m)

contains

  subroutine check(s, what)
    integer(c_int32_t), intent(in) :: s
    character(len=*), intent(in) :: what
    if (s /= SM_OK) then
      print '(5a)', what, ' failed: ', sm_status_str(s), ': ', sm_last_error(m)
      call sm_destroy(m)
      error stop 1
    end if
  end subroutine check

  pure function tet_volume(p) result(v)
    real(c_double), intent(in) :: p(3, 4)
    real(c_double) :: v, u(3), w(3), t(3)
    u = p(:, 2) - p(:, 1)
    w = p(:, 3) - p(:, 1)
    t = p(:, 4) - p(:, 1)
    v = (u(1) * (w(2) * t(3) - w(3) * t(2)) - u(2) * (w(1) * t(3) - w(3) * t(1)) &
         + u(3) * (w(1) * t(2) - w(2) * t(1))) / 6
  end function tet_volume

end program cube
