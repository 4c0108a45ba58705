!> The rule every command follows for every file it writes (results, decks, figures,
!> FFTW wisdom), checked before any work is done:
!>  - an input is never an output, with or without --force;
!>  - a directory is never replaced by a file;
!>  - an existing file is replaced only with --force, and only when femcod wrote it.
!> Whether femcod wrote a file is read from its form, by the kind its name gives:
!>   .h5            an HDF5 file with a `femcod_version` attribute (on / for a checkpoint,
!>                  on /run for a result set)
!>   .csv           a header line of two or more names joined by commas (femcod's headers;
!>                  a line of numbers, a blank line or free text is not one)
!>   .svg           femcod's SVG preamble (XML declaration, <svg>, white background)
!>   .json          a JSON object with a "femcod_version" member
!>   .xdmf          an XDMF document
!>   wisdom         FFTW's own wisdom text, "(fftw-3..." (double or float32)
!>   deck           a two-line deck head: NP PIXEL MAXCONT, then three lines E NU
!> Every write is atomic (femcod_files: a temporary name, then a rename), so a refused or
!> failed command leaves each existing file byte-identical.
module femcod_output_guard
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE, STATUS_IO, STATUS_BAD_INPUT
   use femcod_strings, only: string_type
   use femcod_files, only: canonical_path, path_exists, path_is_directory
   use femcod_hdf5, only: h5_file, h5_open, h5_close, h5_read_string_attribute, h5_exists
   implicit none
   private
   public :: guard_outputs, written_by_femcod, is_fftw_wisdom
   public :: OUTPUT_RESULT, OUTPUT_DECK, OUTPUT_WISDOM

   !> What a file is meant to be, when its name does not say it (a deck or wisdom may have
   !> any name); OUTPUT_RESULT: read the kind from the name's ending.
   integer, parameter :: OUTPUT_RESULT = 1, OUTPUT_DECK = 2, OUTPUT_WISDOM = 3
   !> Bytes read from the head of a file to recognise it.
   integer, parameter :: HEAD_BYTES = 4096

contains

   !> Check the files `names` that a command is about to write, each of the kind `kind`
   !> (OUTPUT_*), against its `inputs` and what exists. STATUS_USAGE (exit 2) when an
   !> output names an input or a directory; STATUS_IO (exit 5) when a file exists and
   !> --force was not given, or when it was but femcod did not write the file.
   subroutine guard_outputs(names, inputs, force, kind, status)
      type(string_type), intent(in) :: names(:), inputs(:)
      logical, intent(in) :: force
      integer, intent(in) :: kind
      type(status_type), intent(inout) :: status
      integer :: m, i
      character(len=:), allocatable :: full
      if (status%code /= 0) return
      do m = 1, size(names)
         full = canonical_path(names(m)%s)
         do i = 1, size(inputs)
            if (full == canonical_path(inputs(i)%s)) then
               call set_error(status, STATUS_USAGE, names(m)%s//" would replace the input "//inputs(i)%s// &
                  "; an input is never an output, even with --force: give another output name")
               return
            end if
         end do
      end do
      do m = 1, size(names)
         if (path_is_directory(names(m)%s)) then
            call set_error(status, STATUS_USAGE, names(m)%s//": is a directory; give a file name for the output")
            return
         end if
         if (.not. path_exists(names(m)%s)) cycle
         if (.not. force) then
            call set_error(status, STATUS_IO, names(m)%s//": exists; not overwritten (use --force to replace it)")
            return
         end if
         if (.not. written_by_femcod(names(m)%s, kind)) then
            call set_error(status, STATUS_IO, names(m)%s//": exists and is not a "//kind_text(names(m)%s, kind)// &
               " that femcod wrote; not replaced, even with --force (remove it yourself or give another name)")
            return
         end if
      end do
   end subroutine guard_outputs

   !> True when the existing file `path` has the form femcod gives a file of this kind.
   logical function written_by_femcod(path, kind) result(ours)
      character(len=*), intent(in) :: path
      integer, intent(in) :: kind
      character(len=:), allocatable :: head
      ours = .false.
      head = file_head(path)
      select case (kind)
      case (OUTPUT_WISDOM)
         ours = is_fftw_wisdom(head)
      case (OUTPUT_DECK)
         ours = is_deck_head(head)
      case default
         if (ends_with(path, ".h5")) then
            ours = is_femcod_hdf5(path, head)
         else if (ends_with(path, ".csv")) then
            ours = is_csv_header(first_line(head))
         else if (ends_with(path, ".svg")) then
            ours = index(head, '<?xml version="1.0" encoding="UTF-8"?>'//new_line('a')// &
               '<svg xmlns="http://www.w3.org/2000/svg"') == 1 .and. &
               index(head, '<rect width="100%" height="100%" fill="white"/>') > 0
         else if (ends_with(path, ".json")) then
            ours = index(adjustl(head), "{") == 1 .and. index(head, '"femcod_version"') > 0
         else if (ends_with(path, ".xdmf")) then
            ours = index(head, "<?xml") == 1 .and. index(head, "<Xdmf") > 0
         end if
      end select
   end function written_by_femcod

   !> FFTW's wisdom text (fftw_export_wisdom_to_filename), double or single precision:
   !> "(fftw-3.x.y fftw_wisdom" or "(fftw-3.x.y fftwf_wisdom". An empty file is not wisdom.
   logical function is_fftw_wisdom(head)
      character(len=*), intent(in) :: head
      character(len=:), allocatable :: line
      line = first_line(head)
      is_fftw_wisdom = index(line, "(fftw-3") == 1 .and. &
         (index(line, " fftw_wisdom") > 0 .or. index(line, " fftwf_wisdom") > 0)
   end function is_fftw_wisdom

   !> The head of a text deck: a label line, "NP PIXEL MAXCONT" and three lines "E NU".
   logical function is_deck_head(head) result(ok)
      character(len=*), intent(in) :: head
      integer :: start, k, np, maxcont, ios
      real(dp) :: pixel, e, nu
      character(len=:), allocatable :: line
      ok = .false.
      start = 1
      line = next_line(head, start)
      line = next_line(head, start)
      read(line, *, iostat=ios) np, pixel, maxcont
      if (ios /= 0) return
      do k = 1, 3
         line = next_line(head, start)
         read(line, *, iostat=ios) e, nu
         if (ios /= 0) return
      end do
      ok = .true.
   end function is_deck_head

   !> femcod's CSV header: two or more names of letters, digits and '_' (not starting with
   !> a digit) joined by commas, such as "step,contacts,load_nN,...".
   pure logical function is_csv_header(line)
      character(len=*), intent(in) :: line
      integer :: k
      logical :: field_start
      is_csv_header = .false.
      if (len_trim(line) == 0) return
      field_start = .true.
      do k = 1, len_trim(line)
         select case (line(k:k))
         case ("a":"z", "A":"Z", "_")
            field_start = .false.
         case ("0":"9")
            if (field_start) return
         case (",")
            if (field_start) return
            field_start = .true.
         case default
            return
         end select
      end do
      is_csv_header = .not. field_start .and. index(line, ",") > 0
   end function is_csv_header

   !> An HDF5 file (its 8-byte signature at the start) with femcod_version on / or /run.
   logical function is_femcod_hdf5(path, head) result(ours)
      character(len=*), intent(in) :: path, head
      character(len=*), parameter :: SIGNATURE = achar(137)//"HDF"//achar(13)//achar(10)//achar(26)//achar(10)
      type(h5_file) :: file
      type(status_type) :: local
      character(len=:), allocatable :: version
      ours = .false.
      if (len(head) < 8) return
      if (head(1:8) /= SIGNATURE) return
      call h5_open(path, file, local, STATUS_BAD_INPUT)
      if (local%code /= 0) return
      version = ""
      call h5_read_string_attribute(file, "/", "femcod_version", 64, version, local, STATUS_BAD_INPUT)
      if (local%code /= 0 .or. len(version) == 0) then
         local = status_type()
         if (h5_exists(file, "/run")) &
            call h5_read_string_attribute(file, "/run", "femcod_version", 64, version, local, STATUS_BAD_INPUT)
      end if
      ours = local%code == 0 .and. len(version) > 0
      call h5_close(file, local)
   end function is_femcod_hdf5

   !> The first HEAD_BYTES bytes of a file ("" when it cannot be read).
   function file_head(path) result(head)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: head
      integer :: unit, ios, size_bytes
      head = ""
      open(newunit=unit, file=path, access="stream", form="unformatted", action="read", status="old", iostat=ios)
      if (ios /= 0) return
      inquire(unit=unit, size=size_bytes)
      if (size_bytes > 0) then
         deallocate(head)
         allocate(character(len=min(size_bytes, HEAD_BYTES)) :: head)
         read(unit, iostat=ios) head
         if (ios /= 0) head = ""
      end if
      close(unit)
   end function file_head

   function first_line(text) result(line)
      character(len=*), intent(in) :: text
      character(len=:), allocatable :: line
      integer :: start
      start = 1
      line = next_line(text, start)
   end function first_line

   !> The line of `text` from `start` (without its CR LF or LF); `start` moves past it.
   function next_line(text, start) result(line)
      character(len=*), intent(in) :: text
      integer, intent(inout) :: start
      character(len=:), allocatable :: line
      integer :: stop_at
      if (start > len(text)) then
         line = ""
         return
      end if
      stop_at = index(text(start:), new_line("a"))
      if (stop_at == 0) then
         line = text(start:)
         start = len(text) + 1
      else
         line = text(start:start + stop_at - 2)
         start = start + stop_at
      end if
      if (len(line) > 0) then
         if (line(len(line):) == achar(13)) line = line(:len(line) - 1)
      end if
   end function next_line

   pure logical function ends_with(text, tail)
      character(len=*), intent(in) :: text, tail
      ends_with = .false.
      if (len(text) >= len(tail)) ends_with = text(len(text) - len(tail) + 1:) == tail
   end function ends_with

   pure function kind_text(path, kind) result(text)
      character(len=*), intent(in) :: path
      integer, intent(in) :: kind
      character(len=:), allocatable :: text
      select case (kind)
      case (OUTPUT_WISDOM)
         text = "FFTW wisdom file"
      case (OUTPUT_DECK)
         text = "deck"
      case default
         if (ends_with(path, ".h5")) then
            text = "result file (HDF5)"
         else
            text = "result file"
         end if
      end select
   end function kind_text
end module femcod_output_guard
