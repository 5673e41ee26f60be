! splinegrid_pitching_fortran: the pitching NACA 0012 coupling loop of client/examples/pitching.cc
! written against the Fortran module `splinegrid` (the C API), as a Fortran solver would.
!
! Imports the 257 x 129 pitching-airfoil C-grid (its 2D view), fits it once to the tolerances by
! boundary kind, then every time step n:
!   1. deforms: the wall turned by alpha(n) = amplitude sin(2 pi n / period) about the quarter
!      chord (0.25, 0), relative to the fitted revision (absolute motions, no drift), on top of
!      the last acknowledged revision (base_revision: a concurrent change is ABORTED), stamped
!      with time n dt and step n;
!   2. evaluates that revision at refinement level `level` into the solver's own array
!      x(2, ni, nj);
!   3. checks every cell's signed area against its sign in the fitted grid (no fold).
! Prints a line per step, latency percentiles (p50, p90, p99, max) of the deform call, the
! server's deformation, the evaluate call and the whole step, and the fold count, in the C++
! example's format; --output FILE writes the last step's evaluated points ("ni nj spatial_dim",
! then one point per line, i fastest). Exit status: 0 clean, 1 folds or refused/failed steps,
! 2 bad arguments, 3 setup (connect, import, fit) failed.
!
! Unlike the C++ example it does not recover a step whose answer was lost in a replica's
! failover (GetGrid by step is not in the C API): such a step counts as failed.
!
! --server defaults to $SPLINEGRID_SERVER, else localhost:50051, as in the C++ example.
!
!   splinegrid_pitching_fortran --server localhost:50051 --steps 100 [--amplitude 10]
!       [--period N] [--dt 0.01] [--level 1] [--check_level 0] [--grid FILE] [--name ID]
!       [--output FILE] [--keep] [--quiet]
program pitching
  use, intrinsic :: iso_c_binding
  use, intrinsic :: iso_fortran_env, only: error_unit, output_unit, int64
  use splinegrid
  implicit none

  real(c_double), parameter :: pi = 3.14159265358979323846_c_double
  character(*), parameter :: usage_line = "usage: splinegrid_pitching_fortran " // &
      "[--server host:port (default: $SPLINEGRID_SERVER, else localhost:50051)] " // &
      "[--steps N] [--amplitude DEG] [--period N] [--dt T] [--level L] [--check_level L] " // &
      "[--grid FILE] [--name ID] [--output FILE] [--keep] [--quiet]"
  character(len=1024) :: server, grid_file, name, output, arg
  integer :: steps, period, level, check_level
  real(c_double) :: amplitude, dt
  logical :: keep, quiet

  type(sg_client) :: client
  type(sg_fit_result) :: fit
  type(sg_grid_info) :: info
  type(sg_deform_options) :: options
  type(sg_deform_result) :: moved
  integer(c_int) :: status
  integer :: extents(3), n, dim, folds, folded_cells, refused, failed, unit, i, j
  integer(c_int64_t) :: previous, evaluated_revision
  real(c_double) :: alpha
  real(c_double), allocatable :: x(:, :, :), reference(:, :), areas(:, :)
  real(c_double), allocatable :: deform_ms(:), server_ms(:), evaluate_ms(:), step_ms(:)
  integer :: n_deform, n_server, n_evaluate, n_step
  integer(int64) :: step_start, evaluate_start

  call parse_arguments()
  if (steps < 1 .or. level < 0 .or. .not. (abs(amplitude) <= huge(amplitude))) then
    write (error_unit, '(a)') "--steps must be >= 1, --level >= 0 and --amplitude finite"
    stop 2, quiet=.true.  ! F2018: no "STOP n" line
  end if
  if (period <= 0) period = steps

  status = sg_connect(client, trim(server))
  if (status /= SG_OK) call fail_setup("connect")

  ! Setup: import (2D view of the two-plane file) and fit to the tolerances by boundary kind.
  status = sg_import_plot3d(client, trim(grid_file), trim(name), planar_view=.true.)
  if (status /= SG_OK) call fail_setup("import")
  status = sg_fit(client, trim(name), 0.0_c_double, fit)
  if (status /= SG_OK) then
    status = sg_delete(client, trim(name))
    call fail_setup("fit")
  end if
  write (output_unit, '("grids/",a," revision ",i0,": ",i0," points -> ",i0, &
      &" control points (",f0.1,"x), max deviation ",es0.3)') trim(name), fit%revision, &
      fit%num_points, fit%num_control_points, &
      real(fit%num_points, c_double) / real(fit%num_control_points, c_double), fit%max_deviation

  ! The solver's array at its resolution, and the cell areas of the fitted grid.
  if (sg_grid_info_get(client, trim(name), info) /= SG_OK) call fail_setup("grid info")
  if (sg_block_extents(client, trim(name), 0, level, extents) /= SG_OK) call fail_setup("extents")
  dim = info%spatial_dim
  if (dim /= 2 .or. extents(3) /= 1) then
    write (error_unit, '(a,i0,a,i0)') "expected a 2D grid, got spatial_dim ", dim, &
        " and nk ", extents(3)
    stop 3, quiet=.true.  ! F2018: no "STOP n" line
  end if
  allocate(x(dim, extents(1), extents(2)))
  allocate(reference(extents(1) - 1, extents(2) - 1), areas(extents(1) - 1, extents(2) - 1))
  status = sg_evaluate(client, trim(name), fit%revision, 0, level, x)
  if (status /= SG_OK) call fail_setup("evaluate")
  call signed_areas(x, reference)
  write (output_unit, '(i0," steps, pitch +-",a," degrees about (0.25, 0), period ",i0, &
      &" steps; ",i0," cells at level ",i0," checked per step")') steps, general(amplitude), period, &
      size(reference), level

  allocate(deform_ms(steps), server_ms(steps), evaluate_ms(steps), step_ms(steps))
  n_deform = 0; n_server = 0; n_evaluate = 0; n_step = 0
  folded_cells = 0; refused = 0; failed = 0
  ! The base of every deformation: the last acknowledged revision (the fit's at first).
  previous = fit%revision
  evaluated_revision = 0
  do n = 1, steps
    alpha = amplitude * sin(2 * pi * n / period)
    step_start = clock()
    options = sg_deform_options(reference_revision=fit%revision, base_revision=previous, &
        time=n * dt, step=n, check_level=check_level, boundary_kind=SG_BOUNDARY_WALL)
    status = sg_deform_rigid(client, trim(name), options, alpha, &
        center=[0.25_c_double, 0.0_c_double, 0.0_c_double], result=moved)
    n_deform = n_deform + 1
    deform_ms(n_deform) = milliseconds_since(step_start)
    if (status /= SG_OK) then
      write (output_unit, '("step ",i0," alpha ",a,": ",a,": ",a)') n, fixed(alpha, 3), &
          sg_status_name(status), sg_last_error(client)
      if (status == SG_FAILED_PRECONDITION) then
        refused = refused + 1
      else
        failed = failed + 1
      end if
      if (status == SG_ABORTED) exit  ! never deform over another client's change
      cycle
    end if
    previous = moved%revision
    n_server = n_server + 1
    server_ms(n_server) = 1e3_c_double * moved%seconds

    evaluate_start = clock()
    status = sg_evaluate(client, trim(name), moved%revision, 0, level, x, &
        revision_out=evaluated_revision)
    n_evaluate = n_evaluate + 1
    evaluate_ms(n_evaluate) = milliseconds_since(evaluate_start)
    if (status /= SG_OK) then
      write (output_unit, '("step ",i0,": evaluate: ",a)') n, sg_last_error(client)
      failed = failed + 1
      cycle
    end if
    call signed_areas(x, areas)
    folds = count(reference /= 0 .and. .not. (areas * reference > 0))
    folded_cells = folded_cells + folds
    n_step = n_step + 1
    step_ms(n_step) = milliseconds_since(step_start)
    if (.not. quiet) then
      write (output_unit, '("step ",i3," t ",a," alpha ",f8.3," revision ",i4, &
          &" min Jacobian ratio ",a," deform ",f7.3," ms evaluate ",f7.3," ms folds ",i0)') &
          n, fixed(n * dt, 3), alpha, moved%revision, fixed(moved%min_jacobian_ratio, 4), &
          deform_ms(n_deform), evaluate_ms(n_evaluate), folds
    end if
  end do

  write (output_unit, '("latency over ",i0," steps, ms:      p50       p90       p99       max")') &
      steps
  call percentile_row("deform", deform_ms(1:n_deform))
  call percentile_row("  (server)", server_ms(1:n_server))
  call percentile_row("evaluate", evaluate_ms(1:n_evaluate))
  call percentile_row("step", step_ms(1:n_step))
  write (output_unit, '("folds: ",i0," (folded cells over all steps), ",i0, &
      &" steps refused by the server, ",i0," failed")') folded_cells, refused, failed
  write (output_unit, '("final revision ",i0,": ",i0," x ",i0," points evaluated")') &
      evaluated_revision, extents(1), extents(2)

  if (len_trim(output) > 0) then
    open (newunit=unit, file=trim(output), status="replace", action="write")
    write (unit, '(i0,1x,i0,1x,i0)') extents(1), extents(2), dim
    do j = 1, extents(2)
      do i = 1, extents(1)
        write (unit, '(es25.17,1x,es25.17)') x(1, i, j), x(2, i, j)
      end do
    end do
    close (unit)
  end if
  if (.not. keep) status = sg_delete(client, trim(name))
  call sg_close(client)
  if (folded_cells /= 0 .or. refused /= 0 .or. failed /= 0) stop 1, quiet=.true.

contains

  subroutine parse_arguments()
    integer :: a, count, length, env_status
    character(len=1024) :: value
    call get_environment_variable("SPLINEGRID_SERVER", server, length, env_status)
    if (env_status == -1) call usage("SPLINEGRID_SERVER is longer than 1024 characters")
    if (env_status /= 0 .or. length == 0) server = "localhost:50051"
    grid_file = SPLINEGRID_SOURCE_DIR // "/../shared/data/grids/n0012_pitch_257x129.fmt"
    name = "pitching-fortran"
    output = ""
    steps = 100; period = 0; level = 1; check_level = 0
    amplitude = 10; dt = 0.01_c_double
    keep = .false.; quiet = .false.
    count = command_argument_count()
    a = 1
    do while (a <= count)
      call get_command_argument(a, arg)
      select case (trim(arg))
      case ("--help", "-h")
        write (output_unit, '(a)') usage_line
        stop 0, quiet=.true.
      case ("--keep")
        keep = .true.
      case ("--quiet")
        quiet = .true.
      case ("--server", "--grid", "--name", "--output", "--steps", "--period", "--level", &
          "--check_level", "--amplitude", "--dt")
        if (a == count) call usage("missing value of " // trim(arg))
        a = a + 1
        call get_command_argument(a, value)
        call take_value(trim(arg), value)
      case default
        call usage("unknown argument " // trim(arg))
      end select
      a = a + 1
    end do
  end subroutine parse_arguments

  ! Sets what `flag` names to `value`.
  subroutine take_value(flag, value)
    character(*), intent(in) :: flag, value
    integer :: io
    io = 0
    select case (flag)
    case ("--server")
      server = value
    case ("--grid")
      grid_file = value
    case ("--name")
      name = value
    case ("--output")
      output = value
    case ("--steps")
      read (value, *, iostat=io) steps
    case ("--period")
      read (value, *, iostat=io) period
    case ("--level")
      read (value, *, iostat=io) level
    case ("--check_level")
      read (value, *, iostat=io) check_level
    case ("--amplitude")
      read (value, *, iostat=io) amplitude
    case ("--dt")
      read (value, *, iostat=io) dt
    end select
    if (io /= 0) call usage(flag // ": not a number: " // trim(value))
  end subroutine take_value

  subroutine usage(message)
    character(*), intent(in) :: message
    write (error_unit, '(a)') message
    write (error_unit, '(a)') usage_line
    stop 2, quiet=.true.  ! F2018: no "STOP n" line
  end subroutine usage

  subroutine fail_setup(what)
    character(*), intent(in) :: what
    write (error_unit, '(a,": ",a,": ",a)') what, sg_status_name(status), sg_last_error(client)
    call sg_close(client)
    stop 3, quiet=.true.  ! F2018: no "STOP n" line
  end subroutine fail_setup

  ! Signed areas of the cells: (p11 - p00) x (p01 - p10) / 2, as the C++ example computes them.
  subroutine signed_areas(p, a)
    real(c_double), intent(in) :: p(:, :, :)
    real(c_double), intent(out) :: a(:, :)
    integer :: ii, jj
    do jj = 1, size(p, 3) - 1
      do ii = 1, size(p, 2) - 1
        a(ii, jj) = 0.5_c_double * ((p(1, ii + 1, jj + 1) - p(1, ii, jj)) * &
            (p(2, ii, jj + 1) - p(2, ii + 1, jj)) - (p(2, ii + 1, jj + 1) - p(2, ii, jj)) * &
            (p(1, ii, jj + 1) - p(1, ii + 1, jj)))
      end do
    end do
  end subroutine signed_areas

  ! `x` as C's "%.<d>f" writes it (gfortran's f0.d leaves out the zero before the point).
  function fixed(x, d) result(s)
    real(c_double), intent(in) :: x
    integer, intent(in) :: d
    character(:), allocatable :: s
    character(len=64) :: buffer
    character(len=16) :: form
    write (form, '("(f0.",i0,")")') d
    write (buffer, form) x
    s = trim(adjustl(buffer))
    if (s(1:1) == ".") then
      s = "0" // s
    else if (len(s) > 1) then
      if (s(1:2) == "-.") s = "-0" // s(2:)
    end if
  end function fixed

  ! `x` with up to 6 decimals and no trailing zeros ("12", "2.5"), close to C's "%g".
  function general(x) result(s)
    real(c_double), intent(in) :: x
    character(:), allocatable :: s
    s = fixed(x, 6)
    do while (s(len(s):len(s)) == "0")
      s = s(1:len(s) - 1)
    end do
    if (s(len(s):len(s)) == ".") s = s(1:len(s) - 1)
  end function general

  integer(int64) function clock()
    call system_clock(clock)
  end function clock

  real(c_double) function milliseconds_since(start)
    integer(int64), intent(in) :: start
    integer(int64) :: now, rate
    call system_clock(now, rate)
    milliseconds_since = 1e3_c_double * real(now - start, c_double) / real(rate, c_double)
  end function milliseconds_since

  ! One row of the latency table: nearest-rank percentiles of `values`.
  subroutine percentile_row(label, values)
    character(*), intent(in) :: label
    real(c_double), intent(in) :: values(:)
    real(c_double) :: sorted(size(values)), p(4)
    character(len=16) :: padded
    integer :: k, m
    real(c_double) :: v
    sorted = values
    do k = 2, size(sorted)  ! insertion sort: a few hundred values
      v = sorted(k)
      m = k - 1
      do while (m >= 1)
        if (sorted(m) <= v) exit
        sorted(m + 1) = sorted(m)
        m = m - 1
      end do
      sorted(m + 1) = v
    end do
    p = 0
    if (size(sorted) > 0) then
      p(1) = sorted(rank(0.5_c_double, size(sorted)))
      p(2) = sorted(rank(0.9_c_double, size(sorted)))
      p(3) = sorted(rank(0.99_c_double, size(sorted)))
      p(4) = sorted(size(sorted))
    end if
    padded = label  ! left-aligned, as %-16s
    write (output_unit, '(2x,a16,4(1x,f9.3))') padded, p
  end subroutine percentile_row

  integer function rank(q, size_)
    real(c_double), intent(in) :: q
    integer, intent(in) :: size_
    rank = min(max(ceiling(q * size_), 1), size_)
  end function rank

end program pitching
