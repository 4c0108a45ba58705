!> Hostile input: every case of test/corpus/MANIFEST runs femcod in its own process
!> (this executable with --femcod) and must end with the documented exit code, a
!> message naming the problem, and no file written under its output prefix.
module test_hostile
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use test_support, only: scratch_path, read_text, file_exists, contains_text, write_text
   use femcod_process, only: process_id, host_name
   use test_results, only: self_command
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_hostile

   character(len=*), parameter :: corpus = "test/corpus"

contains

   subroutine collect_hostile(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("the corpus (test/corpus/MANIFEST): exit code, message, no output", test_corpus), &
         new_unittest("paths with spaces work", test_spaces) &
         ]
   end subroutine collect_hostile

   subroutine test_corpus(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: manifest, line, name, setup, args, fragment, dir, out, message, listing, &
         limit
      integer :: a, b, code, expected, ncases, ios
      manifest = read_text(corpus//"/MANIFEST")
      call check(error, len(manifest) > 0, "reading "//corpus//"/MANIFEST")
      if (allocated(error)) return
      call check(error, file_exists(command_for("bench ")), "the femcod program fpm builds beside the tests: "// &
         command_for("bench "))
      if (allocated(error)) return
      ncases = 0
      a = 1
      do while (a <= len(manifest))
         b = index(manifest(a:), new_line("a"))
         if (b == 0) b = len(manifest) - a + 2
         line = manifest(a:a + b - 2)
         a = a + b
         if (len_trim(line) == 0) cycle
         if (line(1:1) == "#") cycle
         name = field(line, 1)
         setup = field(line, 2)
         read(setup, *, iostat=ios) expected
         call check(error, ios == 0, "MANIFEST: exit code of "//name)
         if (allocated(error)) return
         setup = field(line, 3)
         args = field(line, 4)
         fragment = field(line, 5)
         dir = scratch_path("hostile/"//name)
         call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
         out = dir//"/out"
         call set_up(setup, dir, out, limit)
         call check(error, .not. file_exists(dir//"/SET-UP-FAILED"), name//": the set-up run failed")
         if (allocated(error)) return
         args = expand(args, dir, out)
         fragment = expand(fragment, dir, out)
         call execute_command_line(limit//command_for(args)//" "//args//" > "//dir//".stdout 2> "//dir// &
            ".stderr", exitstat=code)
         message = read_text(dir//".stderr")
         call check(error, code, expected, name//": exit code (message: "//trim(message)//")")
         if (allocated(error)) return
         call check(error, contains_text(message, fragment), name//": the message '"//trim(message)// &
            "' should contain '"//fragment//"'")
         if (allocated(error)) return
         ! Under the case's directory: what the set-up put there, byte for byte, and nothing else.
         listing = file_listing(dir)
         call check(error, listing == read_text(dir//".before"), name//": files changed or left: "//listing// &
            " (before: "//read_text(dir//".before")//")")
         if (allocated(error)) return
         ncases = ncases + 1
      end do
      call check(error, ncases >= 25, "the corpus holds "//to_string(ncases)//" cases, at least 25")
   end subroutine test_corpus

   !> A deck and an output prefix with blanks in their paths.
   subroutine test_spaces(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir
      integer :: code
      dir = scratch_path("dir with spaces")
      call execute_command_line("rm -rf '"//dir//"' && mkdir -p '"//dir//"' && cp "//corpus//"/ok.deck '"// &
         dir//"/my deck.deck'")
      call run_femcod([string_type("run"), string_type(dir//"/my deck.deck"), string_type("-o"), &
         string_type(dir//"/my results"), string_type("--quiet")], code)
      call check(error, code, 0, "run")
      if (allocated(error)) return
      call check(error, file_exists(dir//"/my results.h5") .and. file_exists(dir//"/my results.history.csv"), &
         "results written beside the deck")
   end subroutine test_spaces

   !> The set-up of a case (see MANIFEST), then the listing it leaves in DIR.before.
   !> `limit` is a shell prefix for the run (a file-size limit) or "".
   subroutine set_up(setup, dir, out, limit)
      character(len=*), intent(in) :: setup, dir, out
      character(len=:), allocatable, intent(out) :: limit
      character(len=:), allocatable :: kind, value
      integer :: colon, arrow, code
      limit = ""
      colon = index(setup, ":")
      kind = setup
      value = ""
      if (colon > 0) then
         kind = setup(1:colon - 1)
         value = setup(colon + 1:)
      end if
      select case (kind)
      case ("ckpt")
         call execute_command_line("cp "//corpus//"/"//value//" "//out//".ckpt.h5")
      case ("file")
         ! file:SOURCE>NAME copies the corpus file SOURCE to DIR/NAME.
         arrow = index(value, ">")
         call execute_command_line("cp "//corpus//"/"//value(1:arrow - 1)//" "//dir//"/"//value(arrow + 1:))
      case ("lock")
         ! lock:live names this test process (alive), lock:empty names none.
         if (value == "live") then
            call write_text(out//".lock", to_string(process_id())//" "//host_name()//new_line("a"))
         else
            call write_text(out//".lock", "")
         end if
      case ("run")
         ! run:ARGS runs femcod first; it must succeed.
         call execute_command_line(self_command()//" "//expand(value, dir, out)//" > /dev/null 2>&1", exitstat=code)
         if (code /= 0) call write_text(dir//"/SET-UP-FAILED", "")
      case ("ulimit")
         ! ulimit:N limits every file written to N blocks (512 bytes under dash, 1 KiB under bash).
         limit = "ulimit -f "//value//" && "
      case ("memory")
         ! memory:VALUE runs the case with FEMCOD_MEMORY=VALUE (the memory femcod may use).
         limit = "export FEMCOD_MEMORY="//value//" && "
      end select
      call write_text(dir//".before", file_listing(dir))
   end subroutine set_up

   !> The program a case runs: this executable playing femcod, or for `bench` (which lives
   !> in app/, not in this executable) the femcod program fpm built beside it, from the
   !> same sources: build/<profile>/app/femcod for build/<profile>/test/femcod-test.
   function command_for(args) result(cmd)
      character(len=*), intent(in) :: args
      character(len=:), allocatable :: cmd, self
      integer :: length, at
      cmd = self_command()
      if (index(args, "bench ") /= 1) return
      call get_command_argument(0, length=length)
      allocate(character(len=length) :: self)
      call get_command_argument(0, self)
      at = index(self, "/test/", back=.true.)
      cmd = self(1:at)//"app/femcod"
   end function command_for

   !> Every file under `dir` with its CRC and size (cksum), sorted.
   function file_listing(dir) result(listing)
      character(len=*), intent(in) :: dir
      character(len=:), allocatable :: listing
      call execute_command_line("cd "//dir//" && find . -type f | LC_ALL=C sort | xargs -r cksum > ../"// &
         basename(dir)//".listing")
      listing = read_text(dir//".listing")
   end function file_listing

   function basename(path) result(name)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: name
      name = path(index(path, "/", back=.true.) + 1:)
   end function basename

   !> @C is the corpus directory, @DIR the case's own directory, @OUT its output prefix.
   function expand(args, dir, out) result(r)
      character(len=*), intent(in) :: args, dir, out
      character(len=:), allocatable :: r
      r = replace(replace(replace(args, "@C", corpus), "@OUT", out), "@DIR", dir)
   end function expand

   !> Field k of a " | "-separated line, trimmed.
   function field(line, k) result(f)
      character(len=*), intent(in) :: line
      integer, intent(in) :: k
      character(len=:), allocatable :: f
      integer :: a, b, m
      a = 1
      do m = 1, k - 1
         b = index(line(a:), "|")
         if (b == 0) then
            f = ""
            return
         end if
         a = a + b
      end do
      b = index(line(a:), "|")
      if (b == 0) then
         f = trim(adjustl(line(a:)))
      else
         f = trim(adjustl(line(a:a + b - 2)))
      end if
   end function field

   !> Every occurrence of `from` replaced by `to`.
   function replace(text, from, to) result(r)
      character(len=*), intent(in) :: text, from, to
      character(len=:), allocatable :: r
      integer :: a, b
      r = ""
      a = 1
      do
         b = index(text(a:), from)
         if (b == 0) exit
         r = r//text(a:a + b - 2)//to
         a = a + b - 1 + len(from)
      end do
      r = r//text(a:)
   end function replace
end module test_hostile
