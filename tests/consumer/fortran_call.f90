! The installed Fortran module: its version, a connection to no server (SG_UNAVAILABLE), and an
! import through that failed client (SG_FAILED_PRECONDITION, not connected).
program fortran_call
  use splinegrid
  implicit none
  type(sg_client) :: client
  character(len=256) :: address
  integer :: status
  call get_command_argument(1, address)
  status = sg_connect(client, trim(address), timeout_seconds=5.0d0)
  write (*, '(a,a,a,a,a,a)') "fortran_call: version ", sg_version(), ", ", &
      sg_status_name(status), ": ", sg_last_error(client)
  if (status /= SG_UNAVAILABLE .or. index(sg_last_error(client), trim(address)) == 0) stop 1
  status = sg_import_cgns(client, "wing.cgns", "wing")
  if (status /= SG_FAILED_PRECONDITION .or. index(sg_last_error(client), "not connected") == 0) &
      stop 2
  call sg_close(client)
end program fortran_call
