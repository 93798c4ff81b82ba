!> The Fortran module against the library: string wrappers, parameters, status texts, Fortran
!> callbacks (a spacing returning 0, a batched spacing returning NaN, a progress callback that
!> cancels), outputs before sm_refine with an omitted optional argument, then a real mesh: the
!> sm_quality and sm_region layouts match C, buffer too small, optional markers omitted. The example
!> examples/fortran/cube.f90 (test ffi_example_fortran) meshes and writes a .vtu.
module test_callbacks
  use, intrinsic :: iso_c_binding, only: c_double, c_ptr, c_size_t, c_int32_t
  use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
  implicit none
contains
  function zero_spacing(x, y, z, user_data) bind(C) result(h)
    real(c_double), value :: x, y, z
    type(c_ptr), value :: user_data
    real(c_double) :: h
    h = 0 * (x + y + z)
  end function zero_spacing

  subroutine nan_batch(n, xyz, out, user_data) bind(C)
    integer(c_size_t), value :: n
    real(c_double), intent(in) :: xyz(3, n)
    real(c_double), intent(out) :: out(n)
    type(c_ptr), value :: user_data
    out = 0.2_c_double + 0 * xyz(1, :)
    out(n) = ieee_value(1.0_c_double, ieee_quiet_nan)
  end subroutine nan_batch

  function cancel(fraction, n_vertices, user_data) bind(C) result(stop)
    real(c_double), value :: fraction
    integer(c_size_t), value :: n_vertices
    type(c_ptr), value :: user_data
    integer(c_int32_t) :: stop
    stop = 1
  end function cancel
end module test_callbacks

program test_fortran
  use, intrinsic :: iso_c_binding
  use slivermesh
  use test_callbacks
  implicit none
  type(c_ptr) :: m
  type(sm_quality) :: q
  type(sm_region) :: r(1)
  real(c_double) :: area
  real(c_double) :: v, xyz(3, 8)
  integer(c_int32_t), parameter :: faces(4, 6) = reshape([ &
    0, 2, 3, 1,  4, 5, 7, 6,  0, 1, 5, 4,  2, 6, 7, 3,  0, 4, 6, 2,  1, 3, 7, 5], [4, 6])
  integer(c_int32_t) :: tets(4, 1), status
  integer(c_int32_t), allocatable :: tris(:, :)
  integer :: i, k, failures = 0

  call expect(len(sm_version()) >= 5, 'version')
  call expect(sm_status_str(SM_OK) == 'ok', 'status_str(SM_OK)')
  call expect(sm_status_str(SM_ERR_SPACING) /= 'unknown status', 'status_str(SM_ERR_SPACING)')

  m = sm_create()
  call expect(c_associated(m), 'sm_create')
  do i = 0, 7
    xyz(:, i + 1) = [real(iand(i, 1), c_double), real(iand(ishft(i, -1), 1), c_double), &
                     real(iand(ishft(i, -2), 1), c_double)]
  end do
  call expect(sm_add_vertices(m, xyz, 8_c_size_t) == SM_OK, 'add_vertices')
  do k = 1, 6
    call expect(sm_add_facet(m, faces(:, k), 4_c_size_t, int(k, c_int32_t)) == SM_OK, 'facet')
  end do
  call expect(sm_add_facet(m, [0, 1, 9], 3_c_size_t, 0_c_int32_t) == SM_ERR_INVALID_ARGUMENT, &
              'bad id')
  call expect(index(sm_last_error(m), 'vertex id 9') > 0, 'bad id message')

  call expect(sm_set_param(m, 'rho0', 1.5d0) == SM_OK, 'set rho0')
  call expect(sm_last_error(m) == '', 'message cleared')
  call expect(sm_get_param(m, 'rho0', v) == SM_OK .and. v == 1.5d0, 'get rho0')
  call expect(sm_set_param(m, 'rho00', 1.5d0) == SM_ERR_INVALID_ARGUMENT, 'unknown name')
  call expect(index(sm_last_error(m), 'valid names') > 0, 'unknown name message')
  call expect(sm_set_param(m, 'sigma0', 1d0) == SM_ERR_INVALID_ARGUMENT, 'sigma0 range')
  call expect(sm_get_param(m, 'threads', v) == SM_OK .and. v == 0d0, 'threads default')
  call expect(sm_set_param(m, 'threads', 2d0) == SM_OK, 'set threads')
  call expect(sm_set_param(m, 'threads', -1d0) == SM_ERR_INVALID_ARGUMENT, 'threads range')
  call expect(sm_set_param(m, 'spacing_thread_safe', 1d0) == SM_OK, 'set spacing_thread_safe')
  call expect(sm_set_param(m, 'spacing_thread_safe', 0d0) == SM_OK, 'reset spacing_thread_safe')
  ! A size field whose one tet names a vertex that is not there.
  call expect(sm_set_spacing_mesh(m, [0d0, 0d0, 0d0, 1d0, 0d0, 0d0, 0d0, 1d0, 0d0, 0d0, 0d0, 1d0], &
                                  4_c_size_t, [0, 1, 2, 4], 1_c_size_t, [0.1d0, 0.1d0, 0.1d0, 0.1d0]) &
              == SM_ERR_INVALID_ARGUMENT, 'size field tet out of range')
  call expect(index(sm_last_error(m), 'size field') > 0, 'size field message')

  call expect(sm_get_quality(m, q) == SM_ERR_NOT_REFINED, 'quality before refine')
  call expect(sm_get_tets(m, tets, capacity=1_c_size_t) == SM_ERR_NOT_REFINED, 'tets')
  call expect(sm_num_tets(m) == 0, 'num_tets')
  call expect(sm_write(m, 'never.vtu') == SM_ERR_NOT_REFINED, 'write before refine')
  call expect(sm_write_binary(m, 'never.msh') == SM_ERR_NOT_REFINED, 'binary write before refine')

  call expect(sm_set_spacing_cb(m, c_funloc(zero_spacing), c_null_ptr) == SM_OK, 'spacing cb')
  call expect(sm_refine(m) == SM_ERR_SPACING, 'zero spacing fails')
  call expect(index(sm_last_error(m), 'returned 0 at (0, 0, 0)') > 0, 'zero spacing message')
  call expect(sm_set_spacing_batch_cb(m, c_funloc(nan_batch), c_null_ptr) == SM_OK, 'batch cb')
  call expect(sm_refine(m) == SM_ERR_SPACING, 'NaN spacing fails')
  call expect(index(sm_last_error(m), 'NaN at (1, 1, 1)') > 0, 'NaN spacing message')

  call expect(sm_set_spacing_const(m, 0.3d0) == SM_OK, 'const spacing')
  call expect(sm_set_progress_cb(m, c_funloc(cancel), c_null_ptr) == SM_OK, 'progress cb')
  call expect(sm_refine(m) == SM_ERR_CANCELLED, 'cancel')

  ! A real mesh: the struct layout matches C (size, and figures consistent with the counts).
  call expect(c_sizeof(q) == 168_c_size_t, 'sizeof(sm_quality) == 168 as in C')
  call expect(sm_set_progress_cb(m, c_null_funptr, c_null_ptr) == SM_OK, 'no progress cb')
  status = sm_refine(m)
  call expect(status == SM_OK, 'refine the cube')
  if (status == SM_OK) then
    call expect(sm_get_quality(m, q) == SM_OK, 'quality')
    call expect(q%n_tets == sm_num_tets(m) .and. q%n_tets > 0, 'quality n_tets')
    call expect(q%n_vertices == sm_num_vertices(m), 'quality n_vertices')
    call expect(q%n_boundary_faces == sm_num_boundary_faces(m), 'quality n_boundary_faces')
    call expect(q%min_dihedral_deg > 0 .and. q%min_dihedral_deg <= q%max_dihedral_deg, &
                'dihedral range')
    call expect(q%complete == 0 .or. q%complete == 1, 'complete flag')
    allocate (tris(3, sm_num_boundary_faces(m)))
    call expect(sm_get_boundary_faces(m, tris, capacity=size(tris, 2, c_size_t) - 1) &
                == SM_ERR_BUFFER_TOO_SMALL, 'boundary buffer too small')
    call expect(sm_get_boundary_faces(m, tris, capacity=size(tris, 2, c_size_t)) == SM_OK, &
                'boundary faces, markers omitted')
    call expect(minval(tris) >= 0 .and. maxval(tris) < sm_num_vertices(m), 'boundary ids')
    ! One region (attribute 0), the whole cube; no interfaces.
    call expect(c_sizeof(r) == 40_c_size_t, 'sizeof(sm_region) == 40 as in C')
    call expect(sm_num_regions(m) == 1, 'one region')
    call expect(sm_get_regions(m, r, 1_c_size_t, area) == SM_OK, 'regions, input area omitted')
    call expect(r(1)%attribute == 0 .and. r(1)%tets == sm_num_tets(m), 'region tets')
    call expect(abs(r(1)%volume - 1) < 1d-9 .and. abs(r(1)%input_volume - 1) < 1d-12, &
                'region volume')
    call expect(area == 0, 'no interface')
  end if
  call sm_destroy(m)
  call sm_destroy(c_null_ptr)

  if (failures > 0) then
    print '(i0, a)', failures, ' check(s) failed'
    error stop 1
  end if
  print '(a)', 'test_fortran: all checks passed'

contains

  subroutine expect(ok, what)
    logical, intent(in) :: ok
    character(len=*), intent(in) :: what
    if (.not. ok) then
      if (c_associated(m)) then
        print '(4a)', 'FAILED: ', what, ': ', sm_last_error(m)
      else
        print '(2a)', 'FAILED: ', what
      end if
      failures = failures + 1
    end if
  end subroutine expect

end program test_fortran
