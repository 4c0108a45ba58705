!> The HDF5 deck: the content of the two-line text deck (doc/deck-format.md) as named
!> datasets and attributes of one HDF5 file, for surfaces beyond what a text deck holds and
!> for reading at disk speed. The layout:
!>
!>     /                 attributes format = "femcod deck 1", femcod_version, label
!>     /NP, /MAXCONT     integer scalars
!>     /pixel            real scalar (nm)
!>     /young, /poisson  3 reals each (GPa; 1): lower surface, upper surface, elements
!>     /lower, /upper    NP x NP reals (nm), C order: [i, j] is row i, column j as in the
!>                       text deck (so `--lower NAME.h5:/lower` reads the same surface)
!>
!> Every value is checked as the text reader checks it (femcod_problem's validate_problem),
!> with the file and dataset named. Writing is atomic (a temporary name, then renamed).
module femcod_deck_h5
   use, intrinsic :: ieee_arithmetic, only: ieee_is_finite, ieee_is_nan
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT, STATUS_NUMERICAL
   use femcod_problem, only: contact_problem, validate_problem
   use femcod_hdf5, only: h5_file, h5_create, h5_open, h5_close, h5_write, h5_read, h5_attribute, &
      h5_read_string_attribute, h5_rank_and_dims, h5_exists
   use femcod_files, only: temporary_name, atomic_rename, remove_file
   use femcod_memory, only: available_memory, memory_text
   use femcod_strings, only: int_str
   use femcod_about, only: FEMCOD_VERSION
   implicit none
   private
   public :: write_deck_h5, read_deck_h5, read_deck_h5_header, is_hdf5_file, is_deck_h5, DECK_H5_FORMAT

   !> The format tag on / that makes an HDF5 file a femcod deck.
   character(len=*), parameter :: DECK_H5_FORMAT = "femcod deck 1"
   !> HDF5's 8-byte signature at the start of a file.
   character(len=*), parameter :: SIGNATURE = achar(137)//"HDF"//achar(13)//achar(10)//achar(26)//achar(10)

contains

   !> Whether the file `path` starts with HDF5's signature.
   logical function is_hdf5_file(path)
      character(len=*), intent(in) :: path
      character(len=8) :: head
      integer :: unit, ios
      is_hdf5_file = .false.
      open(newunit=unit, file=path, access="stream", form="unformatted", action="read", status="old", iostat=ios)
      if (ios /= 0) return
      read(unit, iostat=ios) head
      close(unit)
      is_hdf5_file = ios == 0 .and. head == SIGNATURE
   end function is_hdf5_file

   !> Whether `path` is an HDF5 file with the deck's format tag.
   logical function is_deck_h5(path)
      character(len=*), intent(in) :: path
      type(h5_file) :: file
      type(status_type) :: local
      character(len=:), allocatable :: format
      is_deck_h5 = .false.
      if (.not. is_hdf5_file(path)) return
      call h5_open(path, file, local, STATUS_BAD_INPUT)
      if (local%code /= 0) return
      call h5_read_string_attribute(file, "/", "format", 64, format, local, STATUS_BAD_INPUT)
      is_deck_h5 = local%code == 0 .and. format == DECK_H5_FORMAT
      call h5_close(file, local)
   end function is_deck_h5

   !> Write `deck` to `path` as an HDF5 deck: validated first, written under a temporary
   !> name, then renamed, so that `path` is either untouched or complete.
   subroutine write_deck_h5(path, deck, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(in) :: deck
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      character(len=:), allocatable :: tmp
      call validate_problem(deck, status)
      if (status%code /= 0) then
         status%message = path//": "//status%message
         return
      end if
      tmp = temporary_name(path)
      call h5_create(tmp, file, status)
      call h5_attribute(file, "/", "format", DECK_H5_FORMAT, status)
      call h5_attribute(file, "/", "femcod_version", FEMCOD_VERSION, status)
      call h5_attribute(file, "/", "label", deck%label, status)
      call h5_write(file, "/NP", deck%np, "1", status)
      call h5_write(file, "/pixel", deck%pixel, "nm", status)
      call h5_write(file, "/MAXCONT", deck%maxcont, "1", status)
      call h5_write(file, "/young", deck%young, "GPa", status)
      call h5_write(file, "/poisson", deck%poisson, "1", status)
      call h5_write(file, "/lower", deck%lower, "nm", status)
      call h5_write(file, "/upper", deck%upper, "nm", status)
      call h5_close(file, status)
      if (status%code /= 0) then
         call remove_file(tmp)
         return
      end if
      call atomic_rename(tmp, path, status)
   end subroutine write_deck_h5

   !> Read and validate the HDF5 deck `path`. Errors (exit 3) name the file and the
   !> dataset, what was expected and what was found; the heights' memory is checked
   !> against the machine's before they are read (exit 4).
   subroutine read_deck_h5(path, deck, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      call open_header(path, file, deck, status)
      if (status%code /= 0) return
      call check_memory(path, deck%np, status)
      if (status%code == 0) call h5_read(file, "/lower", deck%lower, status, STATUS_BAD_INPUT)
      if (status%code == 0) call h5_read(file, "/upper", deck%upper, status, STATUS_BAD_INPUT)
      call h5_close(file, status)
      if (status%code /= 0) return
      call first_non_finite(path//":/lower", deck%lower, status)
      call first_non_finite(path//":/upper", deck%upper, status)
      if (status%code /= 0) return
      call validate_problem(deck, status)
      if (status%code /= 0) status%message = path//": "//status%message
   end subroutine read_deck_h5

   !> The HDF5 deck `path` without its heights: label, NP, pixel, MAXCONT and the
   !> materials, checked, and /lower and /upper checked to be NP x NP (for a reader that
   !> takes the heights in parts, femcod-mpi's ranks).
   subroutine read_deck_h5_header(path, deck, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      type(contact_problem) :: probe
      call open_header(path, file, deck, status)
      if (status%code /= 0) return
      call h5_close(file, status)
      if (status%code /= 0) return
      ! The scalars' limits, checked on a copy with flat surfaces of one pixel's worth.
      probe = deck
      probe%np = 1
      probe%maxcont = 1
      allocate(probe%lower(1, 1), probe%upper(1, 1))
      probe%lower = 0
      probe%upper = 0
      call validate_problem(probe, status)
      if (status%code /= 0) status%message = path//": "//status%message
   end subroutine read_deck_h5_header

   !> Open `path` and read everything of the deck but the heights, the maps' shapes
   !> checked; `file` is left open (closed on an error).
   subroutine open_header(path, file, deck, status)
      character(len=*), intent(in) :: path
      type(h5_file), intent(out) :: file
      type(contact_problem), intent(inout) :: deck
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: format
      real(dp), allocatable :: values(:)
      integer :: k
      call h5_open(path, file, status, STATUS_BAD_INPUT)
      if (status%code /= 0) return
      call h5_read_string_attribute(file, "/", "format", 64, format, status, STATUS_BAD_INPUT)
      if (status%code /= 0 .or. format /= DECK_H5_FORMAT) then
         status = status_type()
         call set_error(status, STATUS_BAD_INPUT, path//": an HDF5 file, but not a femcod deck (no format "// &
            "attribute '"//DECK_H5_FORMAT//"' on /); heights in an HDF5 dataset go in with --lower "//path// &
            ":/DATASET --pixel D")
         call h5_close(file, status)
         return
      end if
      call h5_read_string_attribute(file, "/", "label", 4096, deck%label, status, STATUS_BAD_INPUT)
      call h5_read(file, "/NP", deck%np, status, STATUS_BAD_INPUT)
      call h5_read(file, "/pixel", deck%pixel, status, STATUS_BAD_INPUT)
      call h5_read(file, "/MAXCONT", deck%maxcont, status, STATUS_BAD_INPUT)
      do k = 1, 2
         if (status%code /= 0) exit
         call h5_read(file, trim(merge("/young  ", "/poisson", k == 1)), values, status, STATUS_BAD_INPUT)
         if (status%code == 0 .and. size(values) /= 3) call set_error(status, STATUS_BAD_INPUT, path//":"// &
            trim(merge("/young  ", "/poisson", k == 1))//": expected 3 values (lower, upper, elements), found "// &
            int_str(size(values)))
         if (status%code /= 0) exit
         if (k == 1) deck%young = values
         if (k == 2) deck%poisson = values
      end do
      if (status%code == 0) call check_maps(file, path, deck%np, status)
      if (status%code == 0 .and. (deck%maxcont < 1 .or. deck%maxcont > deck%np**2)) &
         call set_error(status, STATUS_BAD_INPUT, path//":/MAXCONT: expected an integer from 1 to NP**2 = "// &
         int_str(deck%np**2)//", found "//int_str(deck%maxcont))
      if (status%code /= 0) call h5_close(file, status)
   end subroutine open_header

   !> The first height of `map` (row by row) that is not a finite number, named with its
   !> row and column.
   subroutine first_non_finite(where, map, status)
      character(len=*), intent(in) :: where
      real(dp), intent(in) :: map(:, :)
      type(status_type), intent(inout) :: status
      integer :: i, j
      if (status%code /= 0) return
      if (all(ieee_is_finite(map))) return
      do i = 1, size(map, 1)
         do j = 1, size(map, 2)
            if (.not. ieee_is_finite(map(i, j))) then
               call set_error(status, STATUS_BAD_INPUT, where//": expected finite heights in nm, found "// &
                  trim(merge("NaN     ", "infinity", ieee_is_nan(map(i, j))))//" at row "//int_str(i)// &
                  ", column "//int_str(j))
               return
            end if
         end do
      end do
   end subroutine first_non_finite

   !> Room for the heights: each map once, and once more in the reader's transposition
   !> buffer (exit 4 when the machine has less available).
   subroutine check_memory(path, np, status)
      character(len=*), intent(in) :: path
      integer, intent(in) :: np
      type(status_type), intent(inout) :: status
      integer(i8) :: need, may
      need = 3*8*int(np, i8)**2
      may = available_memory()
      if (may > 0 .and. need > may) call set_error(status, STATUS_NUMERICAL, path//": NP = "//int_str(np)// &
         ": the two height maps need about "//memory_text(need)//" to read, this machine has "//memory_text(may)// &
         " available")
   end subroutine check_memory

   !> /lower and /upper: two-dimensional, NP x NP (NP within the deck's range).
   subroutine check_maps(file, path, np, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: path
      integer, intent(in) :: np
      type(status_type), intent(inout) :: status
      integer :: rank, k
      integer(i8) :: dims(7)
      character(len=*), parameter :: MAPS(2) = ["/lower", "/upper"]
      if (np <= 0 .or. np > 46340) then
         call set_error(status, STATUS_BAD_INPUT, path//":/NP: expected NP from 1 to 46340, found "//int_str(np))
         return
      end if
      do k = 1, 2
         if (.not. h5_exists(file, MAPS(k))) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//MAPS(k)//": missing (expected NP x NP = "// &
               int_str(np)//" x "//int_str(np)//" heights in nm)")
            return
         end if
         call h5_rank_and_dims(file, MAPS(k), rank, dims, status, STATUS_BAD_INPUT)
         if (status%code /= 0) return
         if (rank /= 2 .or. any(dims(1:2) /= np)) then
            call set_error(status, STATUS_BAD_INPUT, path//":"//MAPS(k)//": expected NP x NP = "//int_str(np)// &
               " x "//int_str(np)//" heights, found a "//shape_text(rank, dims)//" dataset")
            return
         end if
      end do
   contains
      function shape_text(r, d) result(text)
         integer, intent(in) :: r
         integer(i8), intent(in) :: d(:)
         character(len=:), allocatable :: text
         integer :: q
         text = ""
         do q = 1, r
            text = text//int_str(d(q))
            if (q < r) text = text//" x "
         end do
         if (r == 0) text = "scalar"
      end function shape_text
   end subroutine check_maps
end module femcod_deck_h5
