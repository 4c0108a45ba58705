!> The HDF5 deck (io/femcod_deck_h5, doc/deck-format.md): the text decks of input/ (the
!> committed files are the reference) go to HDF5 and back to the same bytes; a run reads
!> either form to the same results; every bad HDF5 deck is refused naming the file and the
!> dataset, exit 3; `mkdeck convert` keeps femcod's output rule.
module test_deck_h5
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: read_deck, write_deck
   use femcod_deck_h5, only: DECK_H5_FORMAT
   use femcod_problem, only: contact_problem
   use femcod_hdf5, only: h5_file, h5_create, h5_close, h5_write, h5_attribute
   use femcod_generate, only: VERIFICATION_DECKS
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use test_support, only: scratch_path, read_text, write_text, contains_text, file_exists
   use test_results, only: self_command
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_deck_h5

contains

   subroutine collect_deck_h5(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("every input/ deck: text -> HDF5 -> text gives its bytes, the same problem", test_round_trip), &
         new_unittest("a run reads the HDF5 deck to the text deck's results, byte for byte", test_same_run), &
         new_unittest("bad HDF5 decks: file and dataset named, exit 3, no result", test_bad_decks), &
         new_unittest("mkdeck convert: input never output, only decks replaced, two files", test_convert_rules) &
         ]
   end subroutine collect_deck_h5

   !> Each committed deck of input/ (written by mkdeck, whose text the suite `surfaces`
   !> checks against the thesis' scenes) through `mkdeck convert` to HDF5 and back: the
   !> same bytes; and read_deck of the HDF5 file gives the text deck's problem exactly.
   subroutine test_round_trip(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: text_deck, h5_deck
      type(status_type) :: status
      character(len=:), allocatable :: source, h5, back
      integer :: k, code
      do k = 1, size(VERIFICATION_DECKS)
         source = "input/"//trim(VERIFICATION_DECKS(k))//".deck"
         h5 = scratch_path("h5deck_"//trim(VERIFICATION_DECKS(k))//".h5")
         back = scratch_path("h5deck_"//trim(VERIFICATION_DECKS(k))//".deck")
         call femcod("mkdeck convert "//source//" "//h5//" --force", code)
         call check(error, code, 0, source//" to HDF5")
         if (allocated(error)) return
         call femcod("mkdeck convert "//h5//" "//back//" --force", code)
         call check(error, code, 0, source//" back to text")
         if (allocated(error)) return
         call check(error, read_text(back) == read_text(source) .and. len(read_text(source)) > 0, &
            source//": text -> HDF5 -> text changed the bytes")
         if (allocated(error)) return
         call read_deck(source, text_deck, status)
         call read_deck(h5, h5_deck, status)
         call check(error, status%code, 0, h5//": "//status%message)
         if (allocated(error)) return
         call check(error, h5_deck%label == text_deck%label .and. h5_deck%np == text_deck%np .and. &
            h5_deck%pixel == text_deck%pixel .and. h5_deck%maxcont == text_deck%maxcont .and. &
            all(h5_deck%young == text_deck%young) .and. all(h5_deck%poisson == text_deck%poisson) .and. &
            all(h5_deck%lower == text_deck%lower) .and. all(h5_deck%upper == text_deck%upper), &
            h5//": not the text deck's problem")
         if (allocated(error)) return
      end do
   end subroutine test_round_trip

   !> The rough 32^2 deck of input/, as text and as HDF5, run with the event solver and
   !> with cg: the history, contacts and loads files are the same bytes.
   subroutine test_same_run(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: h5, args
      character(len=*), parameter :: files(3) = [character(len=13) :: ".history.csv", ".contacts.csv", ".loads.csv"]
      integer :: code, k, solver
      h5 = scratch_path("h5run_rough.h5")
      call femcod("mkdeck convert input/rough_selfaffine_32.deck "//h5//" --force", code)
      call check(error, code, 0, "convert")
      if (allocated(error)) return
      do solver = 1, 2
         args = " --loads 2e3,5e3 --force --quiet"
         if (solver == 2) args = " --solver cg"//args
         call femcod("run input/rough_selfaffine_32.deck -o "//scratch_path("h5run_text")//args, code)
         call check(error, code, 0, "the text deck's run")
         if (allocated(error)) return
         call femcod("run "//h5//" -o "//scratch_path("h5run_h5")//args, code)
         call check(error, code, 0, "the HDF5 deck's run")
         if (allocated(error)) return
         do k = 1, size(files)
            if (solver == 2 .and. k == 1) cycle
            call check(error, read_text(scratch_path("h5run_h5")//trim(files(k))) == &
               read_text(scratch_path("h5run_text")//trim(files(k))) .and. &
               len(read_text(scratch_path("h5run_text")//trim(files(k)))) > 20, trim(files(k))//" differs")
            if (allocated(error)) return
         end do
      end do
   end subroutine test_same_run

   !> HDF5 files that are not good decks, each written here with the HDF5 writer: the
   !> run exits 3 with the file and the dataset (or attribute) in its message, and leaves
   !> no result file.
   subroutine test_bad_decks(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=*), parameter :: cases(6) = [character(len=24) :: "no format", "lower missing", &
         "lower 3 x 4", "young of 2", "NaN height", "MAXCONT above NP^2"]
      character(len=*), parameter :: expected(6) = [character(len=72) :: "not a femcod deck", ":/lower: missing", &
         ":/lower: expected NP x NP = 4 x 4 heights", ":/young: expected 3 values", &
         ":/lower: expected finite heights in nm, found NaN at row 2, column 3", &
         ":/MAXCONT: expected an integer from 1 to NP**2 = 16, found 17"]
      character(len=:), allocatable :: path, out, message
      integer :: k, code
      do k = 1, size(cases)
         path = scratch_path("h5bad_"//to_string(k)//".h5")
         out = scratch_path("h5bad_out")
         call write_bad_deck(path, k)
         call execute_command_line("rm -f "//out//".*")
         call femcod("run "//path//" --loads 1 -o "//out//" 2> "//scratch_path("h5bad.err"), code)
         message = read_text(scratch_path("h5bad.err"))
         call check(error, code, 3, trim(cases(k))//": exit code")
         if (allocated(error)) return
         call check(error, contains_text(message, path) .and. contains_text(message, trim(expected(k))), &
            trim(cases(k))//": the message '"//message//"' lacks '"//trim(expected(k))//"'")
         if (allocated(error)) return
         call check(error, .not. file_exists(out//".h5") .and. .not. file_exists(out//".loads.csv"), &
            trim(cases(k))//": a result file was written")
         if (allocated(error)) return
      end do
   end subroutine test_bad_decks

   !> A 4 x 4 HDF5 deck broken in one way (case k of test_bad_decks).
   subroutine write_bad_deck(path, k)
      character(len=*), intent(in) :: path
      integer, intent(in) :: k
      type(h5_file) :: file
      type(status_type) :: status
      real(dp) :: lower(4, 4)
      lower = 1
      if (k == 5) lower(2, 3) = ieee_value(1.0_dp, ieee_quiet_nan)
      call h5_create(path, file, status)
      if (k /= 1) call h5_attribute(file, "/", "format", DECK_H5_FORMAT, status)
      call h5_attribute(file, "/", "label", "bad deck "//to_string(k), status)
      call h5_write(file, "/NP", 4, "1", status)
      call h5_write(file, "/pixel", 1.0_dp, "nm", status)
      call h5_write(file, "/MAXCONT", merge(17, 16, k == 6), "1", status)
      if (k == 4) then
         call h5_write(file, "/young", [200.0_dp, 200.0_dp], "GPa", status)
      else
         call h5_write(file, "/young", [200.0_dp, 200.0_dp, 200.0_dp], "GPa", status)
      end if
      call h5_write(file, "/poisson", [0.3_dp, 0.3_dp, 0.3_dp], "1", status)
      if (k == 3) then
         call h5_write(file, "/lower", lower(1:3, :), "nm", status)
      else if (k /= 2) then
         call h5_write(file, "/lower", lower, "nm", status)
      end if
      call h5_write(file, "/upper", 0*lower(:, :) + 2, "nm", status)
      call h5_close(file, status)
   end subroutine write_bad_deck

   !> `mkdeck convert IN IN` (exit 2), over a file that is not a deck even with --force
   !> (exit 5, the file unchanged), over a deck without --force (exit 5), with one file
   !> (exit 2); over a deck with --force it converts.
   subroutine test_convert_rules(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: deck, other, before
      integer :: code
      deck = scratch_path("h5conv.deck")
      other = scratch_path("h5conv_notes.h5")
      call femcod("mkdeck convert input/sphere_d2.deck "//deck//" --force", code)
      call check(error, code, 0, "a text copy")
      if (allocated(error)) return
      call femcod("mkdeck convert "//deck//" "//deck//" --force", code)
      call check(error, code, 2, "IN as OUT")
      if (allocated(error)) return
      call write_text(other, "notes, not a deck")
      before = read_text(other)
      call femcod("mkdeck convert "//deck//" "//other//" --force", code)
      call check(error, code == 5 .and. read_text(other) == before, "over a file that is not a deck")
      if (allocated(error)) return
      call femcod("mkdeck convert input/sphere_d1.deck "//deck, code)
      call check(error, code, 5, "over a deck without --force")
      if (allocated(error)) return
      call femcod("mkdeck convert "//deck, code)
      call check(error, code, 2, "one file")
      if (allocated(error)) return
      call femcod("mkdeck convert input/sphere_d1.deck "//deck//" --force", code)
      call check(error, code == 0 .and. read_text(deck) == read_text("input/sphere_d1.deck"), &
         "over a deck with --force")
   end subroutine test_convert_rules

   !> femcod with the blank-separated arguments `line` (a redirection at its end is
   !> applied by a shell), in this process or, with a redirection, as a child.
   subroutine femcod(line, code)
      character(len=*), intent(in) :: line
      integer, intent(out) :: code
      type(string_type), allocatable :: args(:)
      if (index(line, " 2>") > 0) then
         call execute_command_line(self_command()//" "//line, exitstat=code)
         return
      end if
      args = words(line)
      call run_femcod(args, code)
   end subroutine femcod

   !> The blank-separated words of `line`.
   function words(line) result(parts)
      character(len=*), intent(in) :: line
      type(string_type), allocatable :: parts(:)
      integer :: k, start
      allocate(parts(0))
      start = 0
      do k = 1, len(line) + 1
         if (k <= len(line)) then
            if (line(k:k) /= " ") then
               if (start == 0) start = k
               cycle
            end if
         end if
         if (start > 0) parts = [parts, string_type(line(start:k - 1))]
         start = 0
      end do
   end function words
end module test_deck_h5
