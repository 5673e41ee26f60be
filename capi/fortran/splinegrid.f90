! splinegrid: Fortran 2003 bindings (iso_c_binding) of the splinegrid C API, capi/splinegrid.h.
!
! Every call is a function returning the C API's status code (SG_OK = 0, else a gRPC code such
! as SG_INVALID_ARGUMENT or SG_NOT_FOUND); sg_last_error(client) is the message of the calling
! thread's last call on that client ("" after a success). Strings are passed as ordinary
! character values (trailing blanks are trimmed); ids come back in character variables.
! Points are real(c_double) arrays laid out as points(spatial_dim, ni, nj, nk); sg_evaluate
! checks an array of rank 2 to 4 against that shape (sg_evaluate_shaped) and takes a rank-1
! array of any size from the needed one up. The caller owns every array.
!
!   use splinegrid
!   type(sg_client) :: client
!   if (sg_connect(client, "localhost:50051") /= SG_OK) stop sg_last_error(client)
!   ...
!   call sg_close(client)
!
! The array arguments use `contiguous` (Fortran 2008, in gfortran since 4.7) so that a section
! is copied into contiguous storage rather than handed to C with strides.
module splinegrid
  use, intrinsic :: iso_c_binding
  implicit none
  private

  ! Status codes (splinegrid.h, the gRPC codes).
  integer(c_int), parameter, public :: SG_OK = 0, SG_CANCELLED = 1, SG_UNKNOWN = 2, &
      SG_INVALID_ARGUMENT = 3, SG_DEADLINE_EXCEEDED = 4, SG_NOT_FOUND = 5, &
      SG_ALREADY_EXISTS = 6, SG_PERMISSION_DENIED = 7, SG_RESOURCE_EXHAUSTED = 8, &
      SG_FAILED_PRECONDITION = 9, SG_ABORTED = 10, SG_OUT_OF_RANGE = 11, &
      SG_UNIMPLEMENTED = 12, SG_INTERNAL = 13, SG_UNAVAILABLE = 14, SG_DATA_LOSS = 15, &
      SG_UNAUTHENTICATED = 16
  ! Boundary kinds and block faces (splinegrid.v1 BoundaryKind, BlockFace).
  integer(c_int32_t), parameter, public :: SG_BOUNDARY_WALL = 1, SG_BOUNDARY_INTERFACE = 2, &
      SG_BOUNDARY_OUTER = 3
  integer(c_int32_t), parameter, public :: SG_FACE_I_MIN = 1, SG_FACE_I_MAX = 2, &
      SG_FACE_J_MIN = 3, SG_FACE_J_MAX = 4, SG_FACE_K_MIN = 5, SG_FACE_K_MAX = 6

  ! Handles: a connection (sg_connect / sg_close) and an open watch (sg_watch_open / _close).
  type, public :: sg_client
    type(c_ptr) :: handle = c_null_ptr
  end type sg_client
  type, public :: sg_watch
    type(c_ptr) :: handle = c_null_ptr
    type(sg_client) :: client  ! whose sg_last_error holds the watch's messages
  end type sg_watch

  ! The C structs, field for field.
  type, bind(c), public :: sg_fit_result
    integer(c_int64_t) :: revision = 0, num_points = 0, num_control_points = 0
    real(c_double) :: max_deviation = 0, seconds = 0, first_layer_change = 0
  end type sg_fit_result
  type, bind(c), public :: sg_fit_options
    real(c_double) :: tolerance = 0, first_layer = 0
  end type sg_fit_options
  type, bind(c), public :: sg_deform_options
    integer(c_int64_t) :: reference_revision = 0, base_revision = 0
    real(c_double) :: time = 0
    integer(c_int64_t) :: step = 0
    integer(c_int32_t) :: check_level = 0, boundary_kind = 0
    real(c_double) :: max_boundary_error = 0
  end type sg_deform_options
  type, bind(c), public :: sg_deform_result
    integer(c_int64_t) :: revision = 0
    real(c_double) :: min_jacobian_ratio = 0, max_jacobian_ratio = 0, seconds = 0
    integer(c_int32_t) :: moved_controls = 0, reserved = 0
    real(c_double) :: boundary_error = 0
  end type sg_deform_result
  type, bind(c), public :: sg_grid_info
    integer(c_int64_t) :: latest_revision = 0
    integer(c_int32_t) :: num_blocks = 0, spatial_dim = 0
  end type sg_grid_info
  type, bind(c), public :: sg_revision_info
    integer(c_int64_t) :: revision = 0, parent_revision = 0, step = 0
    real(c_double) :: time = 0
    integer(c_int32_t) :: origin = 0, reserved = 0
  end type sg_revision_info

  public :: sg_connect, sg_close, sg_last_error, sg_status_name, sg_version
  public :: sg_import_plot3d, sg_import_cgns, sg_import_points, sg_fit, sg_fit_with
  public :: sg_grid_info_get, sg_block_extents
  public :: sg_delete, sg_deform_rigid, sg_deform_points, sg_evaluate
  public :: sg_watch_open, sg_watch_next, sg_watch_cancel, sg_watch_close

  ! Arrays of rank 1 to 4 for the calls that take or fill points.
  interface sg_evaluate
    module procedure sg_evaluate_1, sg_evaluate_2, sg_evaluate_3, sg_evaluate_4
  end interface sg_evaluate
  interface sg_import_points
    module procedure sg_import_points_1, sg_import_points_2, sg_import_points_3, &
        sg_import_points_4
  end interface sg_import_points
  interface sg_deform_points
    module procedure sg_deform_points_1, sg_deform_points_2
  end interface sg_deform_points

  ! The C functions (splinegrid.h).
  interface
    function c_strlen(s) bind(c, name="strlen") result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: s
      integer(c_size_t) :: n
    end function c_strlen
    function c_sg_last_error_copy(client, buffer, size) bind(c, name="sg_last_error_copy") &
        result(n)
      import :: c_ptr, c_size_t
      type(c_ptr), value :: client, buffer
      integer(c_size_t), value :: size
      integer(c_size_t) :: n
    end function c_sg_last_error_copy
    function c_sg_status_name(status) bind(c, name="sg_status_name") result(name)
      import :: c_ptr, c_int
      integer(c_int), value :: status
      type(c_ptr) :: name
    end function c_sg_status_name
    function c_sg_version() bind(c, name="sg_version") result(version)
      import :: c_ptr
      type(c_ptr) :: version
    end function c_sg_version
    function c_sg_connect(target, token, tls_ca_file, timeout_seconds, client) &
        bind(c, name="sg_connect") result(status)
      import :: c_char, c_double, c_ptr, c_int
      character(kind=c_char), dimension(*), intent(in) :: target, token, tls_ca_file
      real(c_double), value :: timeout_seconds
      type(c_ptr), intent(out) :: client
      integer(c_int) :: status
    end function c_sg_connect
    subroutine c_sg_close(client) bind(c, name="sg_close")
      import :: c_ptr
      type(c_ptr), value :: client
    end subroutine c_sg_close
    function c_sg_import_plot3d(client, path, grid_id, planar_view, id, id_size) &
        bind(c, name="sg_import_plot3d") result(status)
      import :: c_ptr, c_char, c_int32_t, c_size_t, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: path, grid_id
      integer(c_int32_t), value :: planar_view
      type(c_ptr), value :: id
      integer(c_size_t), value :: id_size
      integer(c_int) :: status
    end function c_sg_import_plot3d
    function c_sg_import_cgns(client, path, grid_id, id, id_size) &
        bind(c, name="sg_import_cgns") result(status)
      import :: c_ptr, c_char, c_size_t, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: path, grid_id
      type(c_ptr), value :: id
      integer(c_size_t), value :: id_size
      integer(c_int) :: status
    end function c_sg_import_cgns
    function c_sg_import_points(client, grid_id, spatial_dim, extents, points, count, id, &
        id_size) bind(c, name="sg_import_points") result(status)
      import :: c_ptr, c_char, c_int32_t, c_int64_t, c_size_t, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid_id
      integer(c_int32_t), value :: spatial_dim
      integer(c_int32_t), dimension(3), intent(in) :: extents
      type(c_ptr), value :: points
      integer(c_int64_t), value :: count
      type(c_ptr), value :: id
      integer(c_size_t), value :: id_size
      integer(c_int) :: status
    end function c_sg_import_points
    function c_sg_fit_with(client, grid, options, result) bind(c, name="sg_fit_with") &
        result(status)
      import :: c_ptr, c_char, sg_fit_options, sg_fit_result, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      type(sg_fit_options), intent(in) :: options
      type(sg_fit_result), intent(out) :: result
      integer(c_int) :: status
    end function c_sg_fit_with
    function c_sg_fit(client, grid, tolerance, result) bind(c, name="sg_fit") result(status)
      import :: c_ptr, c_char, c_double, sg_fit_result, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      real(c_double), value :: tolerance
      type(sg_fit_result), intent(out) :: result
      integer(c_int) :: status
    end function c_sg_fit
    function c_sg_grid_info_get(client, grid, info) bind(c, name="sg_grid_info_get") &
        result(status)
      import :: c_ptr, c_char, sg_grid_info, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      type(sg_grid_info), intent(out) :: info
      integer(c_int) :: status
    end function c_sg_grid_info_get
    function c_sg_block_extents(client, grid, block, level, extents) &
        bind(c, name="sg_block_extents") result(status)
      import :: c_ptr, c_char, c_int32_t, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      integer(c_int32_t), value :: block, level
      integer(c_int32_t), dimension(3), intent(out) :: extents
      integer(c_int) :: status
    end function c_sg_block_extents
    function c_sg_delete(client, grid) bind(c, name="sg_delete") result(status)
      import :: c_ptr, c_char, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      integer(c_int) :: status
    end function c_sg_delete
    function c_sg_deform_rigid(client, grid, options, angle_degrees, center, translation, &
        result) bind(c, name="sg_deform_rigid") result(status)
      import :: c_ptr, c_char, c_double, sg_deform_options, sg_deform_result, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      type(sg_deform_options), intent(in) :: options
      real(c_double), value :: angle_degrees
      real(c_double), dimension(3), intent(in) :: center, translation
      type(sg_deform_result), intent(out) :: result
      integer(c_int) :: status
    end function c_sg_deform_rigid
    function c_sg_deform_points(client, grid, options, block, face, begin, end, level, &
        points, count, displacements, result) bind(c, name="sg_deform_points") result(status)
      import :: c_ptr, c_char, c_int32_t, c_int64_t, sg_deform_options, sg_deform_result, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      type(sg_deform_options), intent(in) :: options
      integer(c_int32_t), value :: block, face
      integer(c_int32_t), dimension(3), intent(in) :: begin, end
      integer(c_int32_t), value :: level
      type(c_ptr), value :: points
      integer(c_int64_t), value :: count
      integer(c_int32_t), value :: displacements
      type(sg_deform_result), intent(out) :: result
      integer(c_int) :: status
    end function c_sg_deform_points
    function c_sg_evaluate_shaped(client, grid, revision, block, level, points, rank, shape, &
        extents, revision_out) bind(c, name="sg_evaluate_shaped") result(status)
      import :: c_ptr, c_char, c_int64_t, c_int32_t, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      integer(c_int64_t), value :: revision
      integer(c_int32_t), value :: block, level
      type(c_ptr), value :: points
      integer(c_int32_t), value :: rank
      integer(c_int64_t), dimension(4), intent(in) :: shape
      integer(c_int32_t), dimension(3), intent(out) :: extents
      integer(c_int64_t), intent(out) :: revision_out
      integer(c_int) :: status
    end function c_sg_evaluate_shaped
    function c_sg_watch_open(client, grid, after_revision, watch) bind(c, name="sg_watch_open") &
        result(status)
      import :: c_ptr, c_char, c_int64_t, c_int
      type(c_ptr), value :: client
      character(kind=c_char), dimension(*), intent(in) :: grid
      integer(c_int64_t), value :: after_revision
      type(c_ptr), intent(out) :: watch
      integer(c_int) :: status
    end function c_sg_watch_open
    function c_sg_watch_next(watch, info, has_revision) bind(c, name="sg_watch_next") &
        result(status)
      import :: c_ptr, sg_revision_info, c_int32_t, c_int
      type(c_ptr), value :: watch
      type(sg_revision_info), intent(out) :: info
      integer(c_int32_t), intent(out) :: has_revision
      integer(c_int) :: status
    end function c_sg_watch_next
    subroutine c_sg_watch_cancel(watch) bind(c, name="sg_watch_cancel")
      import :: c_ptr
      type(c_ptr), value :: watch
    end subroutine c_sg_watch_cancel
    subroutine c_sg_watch_close(watch) bind(c, name="sg_watch_close")
      import :: c_ptr
      type(c_ptr), value :: watch
    end subroutine c_sg_watch_close
  end interface

contains

  ! `s` without trailing blanks, NUL-terminated.
  pure function c_string(s) result(c)
    character(*), intent(in) :: s
    character(kind=c_char, len=len_trim(s) + 1) :: c
    c = trim(s) // c_null_char
  end function c_string

  ! A copy of the NUL-terminated C string at `p` ("" for a null pointer).
  function f_string(p) result(s)
    type(c_ptr), intent(in) :: p
    character(:), allocatable :: s
    character(kind=c_char), pointer :: chars(:)
    integer :: i, n
    if (.not. c_associated(p)) then
      s = ""
      return
    end if
    n = int(c_strlen(p))
    call c_f_pointer(p, chars, [n])
    allocate(character(n) :: s)
    do i = 1, n
      s(i:i) = chars(i)
    end do
  end function f_string

  ! Copies the C string in `buffer` (NUL-terminated) into `id` (blank-padded).
  subroutine copy_id(buffer, id)
    character(kind=c_char), intent(in) :: buffer(:)
    character(*), intent(out) :: id
    integer :: i
    id = ""
    do i = 1, min(size(buffer), len(id))
      if (buffer(i) == c_null_char) exit
      id(i:i) = buffer(i)
    end do
  end subroutine copy_id

  ! ---- Status ----

  ! The message of this thread's last call on `client` ("" after a success).
  function sg_last_error(client) result(message)
    type(sg_client), intent(in) :: client
    character(:), allocatable :: message
    character(kind=c_char), allocatable, target :: buffer(:)
    integer(c_size_t) :: n
    n = c_sg_last_error_copy(client%handle, c_null_ptr, 0_c_size_t)
    allocate(buffer(n + 1))
    n = c_sg_last_error_copy(client%handle, c_loc(buffer), n + 1)
    message = f_string(c_loc(buffer))
  end function sg_last_error

  ! The code's name, e.g. "NOT_FOUND".
  function sg_status_name(status) result(name)
    integer(c_int), intent(in) :: status
    character(:), allocatable :: name
    name = f_string(c_sg_status_name(status))
  end function sg_status_name

  function sg_version() result(version)
    character(:), allocatable :: version
    version = f_string(c_sg_version())
  end function sg_version

  ! ---- Connection ----

  ! Connects to `target` ("host:port") and checks the server's health within timeout_seconds
  ! (also every later call's deadline; default 120 s). On an error `client` still holds the
  ! message (sg_last_error) and must be closed.
  integer(c_int) function sg_connect(client, target, token, tls_ca_file, timeout_seconds) &
      result(status)
    type(sg_client), intent(out) :: client
    character(*), intent(in) :: target
    character(*), intent(in), optional :: token, tls_ca_file
    real(c_double), intent(in), optional :: timeout_seconds
    character(:), allocatable :: t, ca
    real(c_double) :: timeout
    t = ""
    ca = ""
    timeout = 0
    if (present(token)) t = token
    if (present(tls_ca_file)) ca = tls_ca_file
    if (present(timeout_seconds)) timeout = timeout_seconds
    status = c_sg_connect(c_string(target), c_string(t), c_string(ca), timeout, client%handle)
  end function sg_connect

  subroutine sg_close(client)
    type(sg_client), intent(inout) :: client
    call c_sg_close(client%handle)
    client%handle = c_null_ptr
  end subroutine sg_close

  ! ---- Grids ----

  ! Imports a Plot3D file as a new grid (grid_id "" or absent: the server picks one; planar_view:
  ! a two-plane 3D file as its 2D view); the new grid's id into `id` when present.
  integer(c_int) function sg_import_plot3d(client, path, grid_id, planar_view, id) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: path
    character(*), intent(in), optional :: grid_id
    logical, intent(in), optional :: planar_view
    character(*), intent(out), optional :: id
    character(kind=c_char), allocatable, target :: buffer(:)
    character(:), allocatable :: wanted
    integer(c_int32_t) :: planar
    wanted = ""
    if (present(grid_id)) wanted = grid_id
    planar = 0
    if (present(planar_view)) then
      if (planar_view) planar = 1
    end if
    allocate(buffer(1024))
    status = c_sg_import_plot3d(client%handle, c_string(path), c_string(wanted), planar, &
        c_loc(buffer), int(size(buffer), c_size_t))
    if (present(id)) call copy_id(buffer, id)
  end function sg_import_plot3d

  ! Imports a CGNS file as a new grid (its boundary conditions become the default boundary kinds
  ! of later fits); grid_id and id as for sg_import_plot3d.
  integer(c_int) function sg_import_cgns(client, path, grid_id, id) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: path
    character(*), intent(in), optional :: grid_id
    character(*), intent(out), optional :: id
    character(kind=c_char), allocatable, target :: buffer(:)
    character(:), allocatable :: wanted
    wanted = ""
    if (present(grid_id)) wanted = grid_id
    allocate(buffer(1024))
    status = c_sg_import_cgns(client%handle, c_string(path), c_string(wanted), c_loc(buffer), &
        int(size(buffer), c_size_t))
    if (present(id)) call copy_id(buffer, id)
  end function sg_import_cgns

  integer(c_int) function import_points(client, grid_id, spatial_dim, extents, points, count, &
      id) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid_id
    integer, intent(in) :: spatial_dim, extents(3)
    type(c_ptr), intent(in) :: points
    integer(c_int64_t), intent(in) :: count
    character(*), intent(out), optional :: id
    character(kind=c_char), allocatable, target :: buffer(:)
    allocate(buffer(1024))
    status = c_sg_import_points(client%handle, c_string(grid_id), int(spatial_dim, c_int32_t), &
        int(extents, c_int32_t), points, count, c_loc(buffer), int(size(buffer), c_size_t))
    if (present(id)) call copy_id(buffer, id)
  end function import_points

  ! Imports one block of points(spatial_dim, ni, nj, nk) (extents = [ni, nj, nk]) as a new grid.
  integer(c_int) function sg_import_points_1(client, grid_id, spatial_dim, extents, points, id) &
      result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid_id
    integer, intent(in) :: spatial_dim, extents(3)
    real(c_double), intent(in), contiguous, target :: points(:)
    character(*), intent(out), optional :: id
    status = import_points(client, grid_id, spatial_dim, extents, c_loc(points), &
        int(size(points), c_int64_t), id)
  end function sg_import_points_1
  integer(c_int) function sg_import_points_2(client, grid_id, spatial_dim, extents, points, id) &
      result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid_id
    integer, intent(in) :: spatial_dim, extents(3)
    real(c_double), intent(in), contiguous, target :: points(:, :)
    character(*), intent(out), optional :: id
    status = import_points(client, grid_id, spatial_dim, extents, c_loc(points), &
        int(size(points), c_int64_t), id)
  end function sg_import_points_2
  integer(c_int) function sg_import_points_3(client, grid_id, spatial_dim, extents, points, id) &
      result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid_id
    integer, intent(in) :: spatial_dim, extents(3)
    real(c_double), intent(in), contiguous, target :: points(:, :, :)
    character(*), intent(out), optional :: id
    status = import_points(client, grid_id, spatial_dim, extents, c_loc(points), &
        int(size(points), c_int64_t), id)
  end function sg_import_points_3
  integer(c_int) function sg_import_points_4(client, grid_id, spatial_dim, extents, points, id) &
      result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid_id
    integer, intent(in) :: spatial_dim, extents(3)
    real(c_double), intent(in), contiguous, target :: points(:, :, :, :)
    character(*), intent(out), optional :: id
    status = import_points(client, grid_id, spatial_dim, extents, c_loc(points), &
        int(size(points), c_int64_t), id)
  end function sg_import_points_4

  ! Fits the grid: tolerance > 0 for every point, 0 for the tolerances by boundary kind.
  integer(c_int) function sg_fit(client, grid, tolerance, result) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    real(c_double), intent(in) :: tolerance
    type(sg_fit_result), intent(out) :: result
    status = c_sg_fit(client%handle, c_string(grid), tolerance, result)
  end function sg_fit

  ! sg_fit with `options` (sg_fit_options: tolerance, first_layer).
  integer(c_int) function sg_fit_with(client, grid, options, result) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    type(sg_fit_options), intent(in) :: options
    type(sg_fit_result), intent(out) :: result
    status = c_sg_fit_with(client%handle, c_string(grid), options, result)
  end function sg_fit_with

  integer(c_int) function sg_grid_info_get(client, grid, info) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    type(sg_grid_info), intent(out) :: info
    status = c_sg_grid_info_get(client%handle, c_string(grid), info)
  end function sg_grid_info_get

  ! Point counts of `block` (0-based, as on the server) at refinement `level`.
  integer(c_int) function sg_block_extents(client, grid, block, level, extents) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    integer, intent(in) :: block, level
    integer, intent(out) :: extents(3)
    integer(c_int32_t) :: e(3)
    status = c_sg_block_extents(client%handle, c_string(grid), int(block, c_int32_t), &
        int(level, c_int32_t), e)
    extents = int(e)
  end function sg_block_extents

  integer(c_int) function sg_delete(client, grid) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    status = c_sg_delete(client%handle, c_string(grid))
  end function sg_delete

  ! ---- Deformation ----

  ! Turns the selected boundary by angle_degrees about the z axis through `center` (default
  ! the origin), then moves it by `translation` (default none).
  integer(c_int) function sg_deform_rigid(client, grid, options, angle_degrees, center, &
      translation, result) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    type(sg_deform_options), intent(in) :: options
    real(c_double), intent(in) :: angle_degrees
    real(c_double), intent(in), optional :: center(3), translation(3)
    type(sg_deform_result), intent(out) :: result
    real(c_double) :: c(3), t(3)
    c = 0
    t = 0
    if (present(center)) c = center
    if (present(translation)) t = translation
    status = c_sg_deform_rigid(client%handle, c_string(grid), options, angle_degrees, c, t, &
        result)
  end function sg_deform_rigid

  integer(c_int) function deform_points(client, grid, options, block, face, begin, end, level, &
      points, count, displacements, result) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    type(sg_deform_options), intent(in) :: options
    integer, intent(in) :: block, face, begin(3), end(3), level
    type(c_ptr), intent(in) :: points
    integer(c_int64_t), intent(in) :: count
    logical, intent(in), optional :: displacements
    type(sg_deform_result), intent(out) :: result
    integer(c_int32_t) :: d
    d = 0
    if (present(displacements)) then
      if (displacements) d = 1
    end if
    status = c_sg_deform_points(client%handle, c_string(grid), options, int(block, c_int32_t), &
        int(face, c_int32_t), int(begin, c_int32_t), int(end, c_int32_t), &
        int(level, c_int32_t), points, count, d, result)
  end function deform_points

  ! Moves the points of one face range (begin..end, 0-based original indices) to points(:)
  ! or points(spatial_dim, n) (by them, with displacements = .true.) at refinement `level`.
  integer(c_int) function sg_deform_points_1(client, grid, options, block, face, begin, end, &
      level, points, displacements, result) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    type(sg_deform_options), intent(in) :: options
    integer, intent(in) :: block, face, begin(3), end(3), level
    real(c_double), intent(in), contiguous, target :: points(:)
    logical, intent(in), optional :: displacements
    type(sg_deform_result), intent(out) :: result
    status = deform_points(client, grid, options, block, face, begin, end, level, &
        c_loc(points), int(size(points), c_int64_t), displacements, result)
  end function sg_deform_points_1
  integer(c_int) function sg_deform_points_2(client, grid, options, block, face, begin, end, &
      level, points, displacements, result) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    type(sg_deform_options), intent(in) :: options
    integer, intent(in) :: block, face, begin(3), end(3), level
    real(c_double), intent(in), contiguous, target :: points(:, :)
    logical, intent(in), optional :: displacements
    type(sg_deform_result), intent(out) :: result
    status = deform_points(client, grid, options, block, face, begin, end, level, &
        c_loc(points), int(size(points), c_int64_t), displacements, result)
  end function sg_deform_points_2

  ! ---- Evaluation ----

  integer(c_int) function evaluate(client, grid, revision, block, level, points, array_shape, &
      extents, revision_out) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    integer(c_int64_t), intent(in) :: revision
    integer, intent(in) :: block, level
    type(c_ptr), intent(in) :: points
    integer, intent(in) :: array_shape(:)
    integer, intent(out), optional :: extents(3)
    integer(c_int64_t), intent(out), optional :: revision_out
    integer(c_int32_t) :: e(3)
    integer(c_int64_t) :: r, dims(4)
    dims = 1
    dims(1:size(array_shape)) = int(array_shape, c_int64_t)
    status = c_sg_evaluate_shaped(client%handle, c_string(grid), revision, int(block, c_int32_t), &
        int(level, c_int32_t), points, int(size(array_shape), c_int32_t), dims, e, r)
    if (present(extents)) extents = int(e)
    if (present(revision_out)) revision_out = r
  end function evaluate

  ! Evaluates `block` (0-based) of `revision` (0: the latest) at refinement `level` into
  ! points(spatial_dim, ni, nj, nk), the directions after its last dimension merged into it
  ! (points(spatial_dim, ni, nj) for nk = 1, points(spatial_dim, ni * nj * nk)), or a rank-1
  ! array of that size or larger. An array of another shape (another level's) is
  ! SG_INVALID_ARGUMENT naming both shapes, and nothing is written.
  integer(c_int) function sg_evaluate_1(client, grid, revision, block, level, points, extents, &
      revision_out) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    integer(c_int64_t), intent(in) :: revision
    integer, intent(in) :: block, level
    real(c_double), intent(inout), contiguous, target :: points(:)
    integer, intent(out), optional :: extents(3)
    integer(c_int64_t), intent(out), optional :: revision_out
    status = evaluate(client, grid, revision, block, level, c_loc(points), shape(points), &
        extents, revision_out)
  end function sg_evaluate_1
  integer(c_int) function sg_evaluate_2(client, grid, revision, block, level, points, extents, &
      revision_out) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    integer(c_int64_t), intent(in) :: revision
    integer, intent(in) :: block, level
    real(c_double), intent(inout), contiguous, target :: points(:, :)
    integer, intent(out), optional :: extents(3)
    integer(c_int64_t), intent(out), optional :: revision_out
    status = evaluate(client, grid, revision, block, level, c_loc(points), shape(points), &
        extents, revision_out)
  end function sg_evaluate_2
  integer(c_int) function sg_evaluate_3(client, grid, revision, block, level, points, extents, &
      revision_out) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    integer(c_int64_t), intent(in) :: revision
    integer, intent(in) :: block, level
    real(c_double), intent(inout), contiguous, target :: points(:, :, :)
    integer, intent(out), optional :: extents(3)
    integer(c_int64_t), intent(out), optional :: revision_out
    status = evaluate(client, grid, revision, block, level, c_loc(points), shape(points), &
        extents, revision_out)
  end function sg_evaluate_3
  integer(c_int) function sg_evaluate_4(client, grid, revision, block, level, points, extents, &
      revision_out) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    integer(c_int64_t), intent(in) :: revision
    integer, intent(in) :: block, level
    real(c_double), intent(inout), contiguous, target :: points(:, :, :, :)
    integer, intent(out), optional :: extents(3)
    integer(c_int64_t), intent(out), optional :: revision_out
    status = evaluate(client, grid, revision, block, level, c_loc(points), shape(points), &
        extents, revision_out)
  end function sg_evaluate_4

  ! ---- Watching ----

  ! Opens a watch of the revisions after `after_revision` (0: all stored first, -1: new only).
  integer(c_int) function sg_watch_open(client, grid, after_revision, watch) result(status)
    type(sg_client), intent(in) :: client
    character(*), intent(in) :: grid
    integer(c_int64_t), intent(in) :: after_revision
    type(sg_watch), intent(out) :: watch
    watch%client = client
    status = c_sg_watch_open(client%handle, c_string(grid), after_revision, watch%handle)
  end function sg_watch_open

  ! Blocks until the next revision (has_revision = .true., `info` filled) or the end of the
  ! watch (has_revision = .false.: status SG_OK when it ended without an error).
  integer(c_int) function sg_watch_next(watch, info, has_revision) result(status)
    type(sg_watch), intent(in) :: watch
    type(sg_revision_info), intent(out) :: info
    logical, intent(out) :: has_revision
    integer(c_int32_t) :: has
    status = c_sg_watch_next(watch%handle, info, has)
    has_revision = has /= 0
  end function sg_watch_next

  ! Ends the watch from any thread.
  subroutine sg_watch_cancel(watch)
    type(sg_watch), intent(in) :: watch
    call c_sg_watch_cancel(watch%handle)
  end subroutine sg_watch_cancel

  subroutine sg_watch_close(watch)
    type(sg_watch), intent(inout) :: watch
    call c_sg_watch_close(watch%handle)
    watch%handle = c_null_ptr
  end subroutine sg_watch_close

end module splinegrid
