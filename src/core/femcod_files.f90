!> Small file-system helpers used by the I/O modules (never by the numerical core):
!> atomic replacement of a file by a temporary one, removal, existence and kind.
module femcod_files
   use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char, c_ptr, c_associated, c_f_pointer, c_size_t, &
      c_loc, c_long
   use femcod_kinds, only: i8
   use femcod_status, only: status_type, set_error, STATUS_IO, STATUS_BAD_INPUT
   use femcod_process, only: process_id, host_name, process_alive
   use femcod_strings, only: int_str, string_type
   implicit none
   private
   public :: atomic_rename, remove_file, path_exists, path_is_directory, temporary_name, write_bytes, write_file
   public :: default_prefix, file_part, base_name, read_file, canonical_path, acquire_lock, release_lock, make_directories
   public :: clear_write_error, write_error_cause, os_error_text, MAX_TEXT_BYTES, directory_names

   !> The largest file read_file takes (bytes): 2 GiB less 64 KiB, so that positions in
   !> the text, and positions a few words past them, stay default integers.
   integer, parameter :: MAX_TEXT_BYTES = huge(0) - 65535

   interface
      function c_fopen(path, mode) bind(c, name="fopen") result(stream)
         import :: c_char, c_ptr
         character(kind=c_char), intent(in) :: path(*), mode(*)
         type(c_ptr) :: stream
      end function c_fopen
      function c_fwrite(buffer, size, count, stream) bind(c, name="fwrite") result(written)
         import :: c_ptr, c_size_t
         type(c_ptr), value :: buffer, stream
         integer(c_size_t), value :: size, count
         integer(c_size_t) :: written
      end function c_fwrite
      function c_fclose(stream) bind(c, name="fclose") result(rc)
         import :: c_ptr, c_int
         type(c_ptr), value :: stream
         integer(c_int) :: rc
      end function c_fclose
      function c_errno_location() bind(c, name="__errno_location") result(p)
         import :: c_ptr
         type(c_ptr) :: p
      end function c_errno_location
      function c_strerror(code) bind(c, name="strerror") result(p)
         import :: c_int, c_ptr
         integer(c_int), value :: code
         type(c_ptr) :: p
      end function c_strerror
      function c_list_directory(path, buf, cap) bind(c, name="femcod_list_directory") result(used)
         import :: c_char, c_long
         character(kind=c_char), intent(in) :: path(*)
         character(kind=c_char), intent(out) :: buf(*)
         integer(c_long), value :: cap
         integer(c_long) :: used
      end function c_list_directory
      function c_rename(from, to) bind(c, name="rename") result(rc)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: rc
      end function c_rename
      !> link(2): a second name for a file; fails (EEXIST) if `to` exists, atomically.
      function c_link(from, to) bind(c, name="link") result(rc)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: from(*), to(*)
         integer(c_int) :: rc
      end function c_link
      function c_realpath(path, resolved) bind(c, name="realpath") result(p)
         import :: c_char, c_ptr
         character(kind=c_char), intent(in) :: path(*)
         character(kind=c_char), intent(out) :: resolved(*)
         type(c_ptr) :: p
      end function c_realpath
      function c_mkdir(path, mode) bind(c, name="mkdir") result(rc)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int), value :: mode
         integer(c_int) :: rc
      end function c_mkdir
      function c_remove(path) bind(c, name="remove") result(rc)
         import :: c_char, c_int
         character(kind=c_char), intent(in) :: path(*)
         integer(c_int) :: rc
      end function c_remove
   end interface

contains

   !> Replace `target` by `source` in one step (POSIX rename): readers see the old
   !> file or the complete new one, never a partial result.
   subroutine atomic_rename(source, target, status)
      character(len=*), intent(in) :: source, target
      type(status_type), intent(inout) :: status
      if (c_rename(source//c_null_char, target//c_null_char) /= 0) then
         call set_error(status, STATUS_IO, target//": cannot rename the temporary file "//source//" onto it")
      end if
   end subroutine atomic_rename

   !> Write `text` as the whole of the file `path` (created or truncated). Through C's
   !> stdio, whose fwrite and fclose report a full disk, a quota or a file-size limit:
   !> gfortran 12's WRITE and CLOSE return iostat = 0 when the disk is full and the data
   !> is lost. On failure the partial file is removed.
   subroutine write_bytes(path, text, status)
      character(len=*), intent(in) :: path
      character(len=*), target, intent(in) :: text
      type(status_type), intent(inout) :: status
      type(c_ptr) :: stream
      integer(c_size_t) :: written
      character(len=:), allocatable :: cause
      if (status%code /= 0) return
      call clear_write_error()
      stream = c_fopen(path//c_null_char, "wb"//c_null_char)
      if (.not. c_associated(stream)) then
         cause = write_error_cause()
         if (len(cause) == 0) cause = " (directory missing or not writable)"
         call set_error(status, STATUS_IO, path//": cannot write"//cause)
         return
      end if
      written = 0
      if (len(text) > 0) written = c_fwrite(c_loc(text), 1_c_size_t, int(len(text), c_size_t), stream)
      ! fclose flushes what stdio still holds: its failure loses data as much as fwrite's.
      if (c_fclose(stream) /= 0 .or. written /= int(len(text), c_size_t)) then
         cause = write_error_cause()
         call remove_file(path)
         call set_error(status, STATUS_IO, path//": writing failed"//cause)
      end if
   end subroutine write_bytes

   !> Write `text` as the file `path` all at once: into the temporary `path.part`, then
   !> renamed onto `path`, so that `path` is either untouched or complete.
   subroutine write_file(path, text, status)
      character(len=*), intent(in) :: path, text
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: tmp
      if (status%code /= 0) return
      tmp = temporary_name(path)
      call write_bytes(tmp, text, status)
      if (status%code /= 0) return
      call atomic_rename(tmp, path, status)
      if (status%code /= 0) call remove_file(tmp)
   end subroutine write_file

   !> Remove a file if it exists; errors are ignored (used to clean up temporaries).
   subroutine remove_file(path)
      character(len=*), intent(in) :: path
      integer(c_int) :: rc
      rc = c_remove(path//c_null_char)
   end subroutine remove_file

   !> True when a file or directory of that name exists.
   logical function path_exists(path)
      character(len=*), intent(in) :: path
      inquire(file=path, exist=path_exists)
   end function path_exists

   !> True when `path` names a directory (it can be opened as `path/.`).
   logical function path_is_directory(path)
      character(len=*), intent(in) :: path
      inquire(file=path//"/.", exist=path_is_directory)
   end function path_is_directory

   !> The temporary name beside `path` (`path.part`). It is the same for every run, so
   !> the leftovers of a run killed while writing are replaced by the next one instead
   !> of piling up (two runs writing the same result at once would clash anyway).
   function temporary_name(path) result(tmp)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: tmp
      tmp = path//".part"
   end function temporary_name

   !> The file name without its directory.
   pure function base_name(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      name = path(index(path, "/", back=.true.) + 1:)
   end function base_name

   !> The file part of `FILE.h5:/dataset` (the path itself for other files).
   function file_part(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      integer :: colon
      colon = index(path, ":/", back=.true.)
      name = path
      if (colon > 0) name = path(1:colon - 1)
   end function file_part

   !> The default output prefix of an input: its file name without directory and
   !> without a known extension (.deck, .txt, .dat, .asc, .h5, .hdf5, .csv).
   function default_prefix(path) result(prefix)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: prefix
      integer :: slash
      slash = index(path, "/", back=.true.)
      prefix = path(slash + 1:)
      slash = index(prefix, ".", back=.true.)
      if (slash > 1) then
         select case (prefix(slash:))
         case (".deck", ".txt", ".dat", ".asc", ".h5", ".hdf5", ".csv")
            prefix = prefix(1:slash - 1)
         end select
      end if
   end function default_prefix

   !> The bytes of a whole input file. `what` names the file in messages ("a deck
   !> file"); a missing file, a directory, an unreadable or empty file is an error
   !> (STATUS_BAD_INPUT) saying which.
   subroutine read_file(path, what, text, status)
      character(len=*), intent(in) :: path, what
      character(len=:), allocatable, intent(out) :: text
      type(status_type), intent(inout) :: status
      integer :: unit, ios
      integer(i8) :: nbytes
      if (path_is_directory(path)) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected "//what//", found a directory")
         return
      end if
      if (.not. path_exists(path)) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected "//what//", found no such file")
         return
      end if
      call clear_write_error()
      open(newunit=unit, file=path, access="stream", form="unformatted", action="read", status="old", iostat=ios)
      if (ios /= 0) then
         call set_error(status, STATUS_BAD_INPUT, path//": expected "//what//", cannot open it ("//os_error_text()//")")
         return
      end if
      inquire(unit=unit, size=nbytes)
      if (nbytes <= 0) then
         close(unit)
         call set_error(status, STATUS_BAD_INPUT, path//":1: expected "//what//", found an empty file")
         return
      end if
      ! Text is held whole and indexed by default integers (gfortran's LEN is one too): a
      ! larger file would be read wrongly, not refused.
      if (nbytes > MAX_TEXT_BYTES) then
         close(unit)
         call set_error(status, STATUS_BAD_INPUT, path//": expected "//what//" of at most "// &
            trim(i8_text(int(MAX_TEXT_BYTES, i8)))//" bytes (2 GiB less 64 KiB), found "//trim(i8_text(nbytes))// &
            " bytes; give larger surfaces as an HDF5 dataset (--lower FILE.h5:/DATASET)")
         return
      end if
      allocate(character(len=nbytes) :: text, stat=ios)
      if (ios /= 0) then
         close(unit)
         call set_error(status, STATUS_BAD_INPUT, path//": cannot hold its "//trim(i8_text(nbytes))//" bytes in memory")
         return
      end if
      read(unit, iostat=ios) text
      close(unit)
      if (ios /= 0) call set_error(status, STATUS_BAD_INPUT, path//": expected "//what//", reading failed")
   contains
      function i8_text(v) result(t)
         integer(i8), intent(in) :: v
         character(len=24) :: t
         write(t, '(i0)') v
      end function i8_text
   end subroutine read_file

   !> The absolute path of a file with every link and "." or ".." resolved, also for a
   !> file that does not exist yet (its directory resolved, its name appended); the path
   !> as given when even the directory cannot be resolved.
   function canonical_path(path) result(full)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: full
      character(kind=c_char, len=4096) :: buf
      integer :: slash, k
      full = path
      if (c_associated(c_realpath(path//c_null_char, buf))) then
         k = index(buf, c_null_char)
         full = buf(1:k - 1)
         return
      end if
      slash = index(path, "/", back=.true.)
      if (slash == 0) then
         if (.not. c_associated(c_realpath("."//c_null_char, buf))) return
         k = index(buf, c_null_char)
         full = buf(1:k - 1)//"/"//path
      else if (c_associated(c_realpath(path(1:max(slash - 1, 1))//c_null_char, buf))) then
         k = index(buf, c_null_char)
         full = buf(1:k - 1)//"/"//path(slash + 1:)
         if (slash == 1) full = "/"//path(2:)
      end if
   end function canonical_path

   !> Take the lock file `path` for this process: created only if it does not exist
   !> (atomically), holding "PID HOST". A lock of a process that no longer runs on this
   !> host is taken over (`notice` says so); a live one is an error naming its holder.
   subroutine acquire_lock(path, status, notice)
      character(len=*), intent(in) :: path
      type(status_type), intent(inout) :: status
      character(len=:), allocatable, intent(out) :: notice
      character(len=:), allocatable :: mine
      integer :: unit, ios, pid, attempt, cut
      character(len=256) :: holder_host
      notice = ""
      if (status%code /= 0) return
      ! The line "PID HOST" is written under a name of this process's own, then linked to
      ! `path` (link fails if `path` exists: an exclusive create), so that the lock
      ! never exists without its line. Created first and filled after, a run killed in
      ! between left an empty lock that every later run refused (the SIGKILL test caught it).
      mine = path//"."//int_str(process_id())
      call write_bytes(mine, int_str(process_id())//" "//host_name()//new_line("a"), status)
      if (status%code /= 0) then
         call remove_file(mine)
         cut = index(status%message, ": writing failed")
         if (cut > 0) then
            status%message = path//": writing the lock file failed"//status%message(cut + 16:)//"; nothing was run"
         else
            status = status_type()
            call set_error(status, STATUS_IO, path//": cannot write the lock file (directory missing or not "// &
               "writable); nothing was run")
         end if
         return
      end if
      do attempt = 1, 2
         if (c_link(mine//c_null_char, path//c_null_char) == 0) then
            call remove_file(mine)
            return
         end if
         if (.not. path_exists(path)) exit
         ! Held: by whom?
         pid = 0
         holder_host = ""
         open(newunit=unit, file=path, status="old", action="read", iostat=ios)
         if (ios == 0) then
            read(unit, *, iostat=ios) pid, holder_host
            close(unit)
         end if
         if (ios /= 0) then
            call remove_file(mine)
            call set_error(status, STATUS_IO, path//": a lock file that names no process (""PID HOST"" expected); "// &
               "remove it if no run writes these results")
            return
         end if
         if (trim(holder_host) == host_name() .and. .not. process_alive(pid)) then
            call remove_file(path)
            notice = path//": taken over from process "//int_str(pid)//", which no longer runs"
            cycle
         end if
         call remove_file(mine)
         call set_error(status, STATUS_IO, path//": another run writes these results (process "//int_str(pid)// &
            " on "//trim(holder_host)//"); wait for it, or remove the lock if that run is gone")
         return
      end do
      call remove_file(mine)
      call set_error(status, STATUS_IO, path//": cannot write the lock file (directory missing or not writable); "// &
         "nothing was run")
   end subroutine acquire_lock

   !> Remove this process's lock file (a lock of another process is left alone).
   subroutine release_lock(path)
      character(len=*), intent(in) :: path
      integer :: unit, ios, pid
      open(newunit=unit, file=path, status="old", action="read", iostat=ios)
      if (ios /= 0) return
      read(unit, *, iostat=ios) pid
      close(unit)
      if (ios == 0 .and. pid == process_id()) call remove_file(path)
   end subroutine release_lock

   !> Make the directory `path` and its missing parents (mode 0777 less the umask).
   subroutine make_directories(path, status)
      character(len=*), intent(in) :: path
      type(status_type), intent(inout) :: status
      integer :: k
      integer(c_int) :: rc
      character(len=:), allocatable :: cause
      if (status%code /= 0 .or. path_is_directory(path)) return
      cause = ""
      do k = 2, len(path) + 1
         if (k <= len(path)) then
            if (path(k:k) /= "/") cycle
         end if
         if (.not. path_is_directory(path(1:k - 1))) then
            rc = c_mkdir(path(1:k - 1)//c_null_char, int(o'777', c_int))
            ! The system's own reason, at the first part it could not make.
            if (rc /= 0 .and. cause == "") cause = " ("//path(1:k - 1)//": "//os_error_text()//")"
         end if
      end do
      if (.not. path_is_directory(path)) call set_error(status, STATUS_IO, path//": cannot make the directory"//cause)
   end subroutine make_directories

   !> The C library's text for its last error (strerror(errno)), "unknown cause" when
   !> errno is 0.
   function os_error_text() result(message)
      character(len=:), allocatable :: message
      integer(c_int), pointer :: errno
      character(kind=c_char), pointer :: text(:)
      integer :: k
      call c_f_pointer(c_errno_location(), errno)
      message = "unknown cause"
      if (errno == 0) return
      call c_f_pointer(c_strerror(errno), text, [256])
      message = ""
      do k = 1, size(text)
         if (text(k) == c_null_char) exit
         message = message//text(k)
      end do
   end function os_error_text

   !> The names in directory `path` (not "." and ".."), sorted by byte value (by
   !> femcod_directory.c's scandir); an error (STATUS_BAD_INPUT) when it cannot be read.
   subroutine directory_names(path, names, status)
      character(len=*), intent(in) :: path
      type(string_type), allocatable, intent(out) :: names(:)
      type(status_type), intent(inout) :: status
      character(kind=c_char, len=:), allocatable :: buf
      integer(c_long) :: used
      integer :: start, k
      allocate(names(0))
      if (status%code /= 0) return
      allocate(character(kind=c_char, len=65536) :: buf)
      used = c_list_directory(path//c_null_char, buf, int(len(buf), c_long))
      if (used > len(buf)) then
         deallocate(buf)
         allocate(character(kind=c_char, len=used + 4096) :: buf)
         used = c_list_directory(path//c_null_char, buf, int(len(buf), c_long))
      end if
      if (used < 0 .or. used > len(buf)) then
         call set_error(status, STATUS_BAD_INPUT, path//": cannot list the directory ("//os_error_text()//")")
         return
      end if
      start = 1
      do k = 1, int(used)
         if (buf(k:k) /= new_line("a")) cycle
         names = [names, string_type(buf(start:k - 1))]
         start = k + 1
      end do
   end subroutine directory_names

   !> Forget the C library's last error (errno = 0) before a write whose cause
   !> write_error_cause may have to tell.
   subroutine clear_write_error()
      integer(c_int), pointer :: errno
      call c_f_pointer(c_errno_location(), errno)
      errno = 0
   end subroutine clear_write_error

   !> Why a write failed, when the C library says it is the device's fault:
   !> " (No space left on device)" for ENOSPC, EDQUOT (quota), EFBIG (the job's
   !> file-size limit), EIO and EROFS; "" otherwise (a library's failure of its own).
   function write_error_cause() result(cause)
      character(len=:), allocatable :: cause
      integer(c_int), parameter :: EIO = 5, EFBIG = 27, ENOSPC = 28, EROFS = 30, EDQUOT = 122
      integer(c_int), pointer :: errno
      cause = ""
      call c_f_pointer(c_errno_location(), errno)
      if (all(errno /= [EIO, EFBIG, ENOSPC, EROFS, EDQUOT])) return
      cause = " ("//os_error_text()//")"
   end function write_error_cause
end module femcod_files
