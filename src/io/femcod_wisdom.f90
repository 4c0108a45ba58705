!> FFTW wisdom files for `--fftw-wisdom FILE` (I/O, used by the command-line layer only):
!> the plans FFTW measured (FFTW_MEASURE) are kept in FILE (double precision) and
!> FILE.float32 (single precision), so that later runs on the same sizes plan at once.
module femcod_wisdom
   use, intrinsic :: iso_c_binding, only: c_int, c_null_char
   use femcod_status, only: status_type
   use femcod_fftw, only: fftw_import_wisdom_from_filename, fftwf_import_wisdom_from_filename, &
      fftw_export_wisdom_to_filename, fftwf_export_wisdom_to_filename
   use femcod_files, only: atomic_rename, path_exists, temporary_name, remove_file
   use femcod_status, only: set_error, STATUS_IO
   implicit none
   private
   public :: load_wisdom, save_wisdom

contains

   !> Read the wisdom kept in `path` (and path.float32), when the files exist. `loaded`
   !> is true when FFTW accepted the double-precision file.
   subroutine load_wisdom(path, loaded)
      character(len=*), intent(in) :: path
      logical, intent(out) :: loaded
      integer(c_int) :: ok
      loaded = .false.
      if (path_exists(path)) then
         ok = fftw_import_wisdom_from_filename(path//c_null_char)
         loaded = ok /= 0
      end if
      if (path_exists(path//".float32")) ok = fftwf_import_wisdom_from_filename(path//".float32"//c_null_char)
   end subroutine load_wisdom

   !> Write FFTW's wisdom to `path` and path.float32 (each under a temporary name, then
   !> renamed).
   subroutine save_wisdom(path, status)
      character(len=*), intent(in) :: path
      type(status_type), intent(inout) :: status
      call save_one(path, .true.)
      if (status%code == 0) call save_one(path//".float32", .false.)
   contains
      subroutine save_one(target, double)
         character(len=*), intent(in) :: target
         logical, intent(in) :: double
         character(len=:), allocatable :: tmp
         integer(c_int) :: ok
         tmp = temporary_name(target)
         if (double) then
            ok = fftw_export_wisdom_to_filename(tmp//c_null_char)
         else
            ok = fftwf_export_wisdom_to_filename(tmp//c_null_char)
         end if
         if (ok == 0) then
            call set_error(status, STATUS_IO, target//": cannot write the FFTW wisdom")
            call remove_file(tmp)
            return
         end if
         call atomic_rename(tmp, target, status)
      end subroutine save_one
   end subroutine save_wisdom
end module femcod_wisdom
