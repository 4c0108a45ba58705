!> The shape of src/ (doc/architecture.md): the layers core < model < legacy < solvers <
!> io < studies < cli < capi, each a folder; a module uses only its own layer and those below.
!> femcod-mpi's modules (mpi/src, built apart with MPI) are one more layer on top, and the
!> programs with their benchmarks (app/, mpi/app/) the last: nothing below uses them.
!> The numerical core keeps no state between calls (no module-level save variables) and
!> never stops the program. No routine is longer than a reader can hold (150 lines), but
!> those listed as not yet split, a list that may only shrink.
module test_architecture
   use femcod_strings, only: string_type, lower_case
   use test_support, only: scratch_path, read_text
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_architecture

   character(len=*), parameter :: LAYERS(10) = [character(len=7) :: "core", "model", "legacy", "solvers", "io", &
      "studies", "cli", "capi", "mpi", "app"]

   !> The longest a routine may be (lines, from its first line to its end statement, its
   !> contained procedures included).
   integer, parameter :: MAX_ROUTINE_LINES = 150
   !> The routines longer than that (file and name), each to be split: the test fails
   !> when one of them is no longer long, so the list only shrinks. Empty since issue 34
   !> split the last five (read_nanoscope, adhesive_cg, read_deck, solve_legacy,
   !> read_ascii_matrix).
   character(len=*), parameter :: LONG_ROUTINES(*) = [character(len=64) :: ]

contains

   subroutine collect_architecture(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("every use points to the same layer or one below", test_layers), &
         new_unittest("no module-level save variables, no stop in src/", test_no_state), &
         new_unittest("no routine longer than 150 lines in src/, mpi/, app/ (but the listed)", test_routine_length), &
         new_unittest("the numerical layers (model, legacy, solvers) do no I/O", test_numerical_no_io), &
         new_unittest("doc/architecture.md names every module in its layer, and no other", test_module_table) &
         ]
   end subroutine collect_architecture

   !> doc/architecture.md's table of modules: a row `| LAYER | `NAME` | ... |` for every
   !> module of src/ and mpi/src/, in its folder's layer, and no row for a module that
   !> does not exist.
   subroutine test_module_table(error)
      type(error_type), allocatable, intent(out) :: error
      type(string_type), allocatable :: files(:), mods(:), names(:)
      character(len=:), allocatable :: doc, line, name
      integer :: f, m, start, k, a, b
      doc = read_text("doc/architecture.md")
      files = sources()
      allocate(names(0))
      do f = 1, size(files)
         call statements(read_text(files(f)%s), "module", mods)
         do m = 1, size(mods)
            names = [names, mods(m)]
            call check(error, index(doc, "| "//trim(LAYERS(layer_of(files(f)%s)))//" | `"//mods(m)%s//"` |") > 0, &
               "doc/architecture.md has no row for "//mods(m)%s//" in layer "//trim(LAYERS(layer_of(files(f)%s))))
            if (allocated(error)) return
         end do
      end do
      call check(error, size(names) > 80, "the modules are found ("//to_string(size(names))//")")
      if (allocated(error)) return
      start = 1
      do k = 1, len(doc)
         if (doc(k:k) /= new_line("a")) cycle
         line = doc(start:k - 1)
         start = k + 1
         a = index(line, " | `femcod_")
         if (index(line, "| ") /= 1 .or. a == 0) cycle
         b = index(line(a + 4:), "`")
         if (b == 0) cycle
         name = line(a + 4:a + 2 + b)
         call check(error, any([(names(m)%s == name, m = 1, size(names))]), &
            "doc/architecture.md names "//name//", which no source defines")
         if (allocated(error)) return
      end do
   end subroutine test_module_table

   !> The source files under src/ and mpi/src/ (one per line), from `find`; with
   !> `programs`, those of app/ and mpi/app/ too.
   function sources(programs) result(files)
      logical, intent(in), optional :: programs
      type(string_type), allocatable :: files(:)
      character(len=:), allocatable :: list, text, folders
      integer :: start, k
      list = scratch_path("sources.txt")
      folders = "src mpi/src"
      if (present(programs)) then
         if (programs) folders = folders//" app mpi/app"
      end if
      call execute_command_line("find "//folders//" -name '*.[fF]90' | sort > "//list)
      text = read_text(list)
      allocate(files(0))
      start = 1
      do k = 1, len(text)
         if (text(k:k) == new_line("a")) then
            files = [files, string_type(text(start:k - 1))]
            start = k + 1
         end if
      end do
   end function sources

   !> The layer of a path src/LAYER/file, or mpi/src/file (0 when not a layer folder).
   integer function layer_of(path)
      character(len=*), intent(in) :: path
      integer :: k
      layer_of = 0
      do k = 1, size(LAYERS)
         if (index(path, "src/"//trim(LAYERS(k))//"/") == 1) layer_of = k
      end do
      if (index(path, "mpi/src/") == 1) layer_of = size(LAYERS) - 1
      if (index(path, "app/") == 1 .or. index(path, "mpi/app/") == 1) layer_of = size(LAYERS)
   end function layer_of

   !> The lower-case words after "module" and "use" at the start of each code line.
   subroutine statements(text, keyword, names)
      character(len=*), intent(in) :: text, keyword
      type(string_type), allocatable, intent(out) :: names(:)
      character(len=:), allocatable :: line, word
      integer :: start, k, e
      allocate(names(0))
      start = 1
      do k = 1, len(text)
         if (text(k:k) /= new_line("a")) cycle
         line = lower_case(adjustl(text(start:k - 1)))
         start = k + 1
         if (index(line, keyword//" ") /= 1) cycle
         word = adjustl(line(len(keyword) + 2:))
         e = scan(word, " ,!")
         if (e > 0) word = word(1:e - 1)
         if (keyword == "module" .and. (word == "procedure" .or. word == "function" .or. word == "subroutine")) cycle
         names = [names, string_type(word)]
      end do
   end subroutine statements

   subroutine test_layers(error)
      type(error_type), allocatable, intent(out) :: error
      type(string_type), allocatable :: files(:), mods(:), uses(:), module_name(:)
      integer, allocatable :: module_layer(:)
      character(len=:), allocatable :: text
      integer :: f, u, m, found
      files = sources(programs=.true.)
      call check(error, size(files) > 40, "the sources are found")
      if (allocated(error)) return
      allocate(module_name(0), module_layer(0))
      do f = 1, size(files)
         call check(error, layer_of(files(f)%s) > 0, files(f)%s//" lies in a layer folder")
         if (allocated(error)) return
         call statements(read_text(files(f)%s), "module", mods)
         do m = 1, size(mods)
            module_name = [module_name, mods(m)]
            module_layer = [module_layer, layer_of(files(f)%s)]
         end do
      end do
      do f = 1, size(files)
         text = read_text(files(f)%s)
         call statements(text, "use", uses)
         do u = 1, size(uses)
            if (index(uses(u)%s, "femcod_") /= 1) cycle
            found = 0
            do m = 1, size(module_name)
               if (module_name(m)%s == uses(u)%s) found = m
            end do
            call check(error, found > 0, files(f)%s//" uses "//uses(u)%s//", found in no source")
            if (allocated(error)) return
            call check(error, module_layer(found) <= layer_of(files(f)%s), files(f)%s//" ("// &
               trim(LAYERS(layer_of(files(f)%s)))//") uses "//uses(u)%s//" ("//trim(LAYERS(module_layer(found)))//")")
            if (allocated(error)) return
         end do
      end do
   end subroutine test_layers

   subroutine test_no_state(error)
      type(error_type), allocatable, intent(out) :: error
      type(string_type), allocatable :: files(:)
      character(len=:), allocatable :: text, line
      integer :: f, start, k
      logical :: in_procedure, in_type
      files = sources()
      do f = 1, size(files)
         text = read_text(files(f)%s)
         start = 1
         in_procedure = .false.
         in_type = .false.
         do k = 1, len(text)
            if (text(k:k) /= new_line("a")) cycle
            line = lower_case(adjustl(text(start:k - 1)))
            start = k + 1
            if (index(line, "contains") == 1) in_procedure = .true.
            if (index(line, "!") == 1) cycle
            call check(error, index(line, "stop ") /= 1 .and. index(line, "error stop") /= 1 .and. line /= "stop", &
               files(f)%s//": a stop statement")
            if (allocated(error)) return
            if (in_procedure) cycle
            ! Derived-type components may have default values; module variables may not.
            if (index(line, "type ::") == 1 .or. index(line, "type, ") == 1) in_type = .true.
            if (index(line, "end type") == 1) in_type = .false.
            call check(error, index(line, ", save ::") == 0 .and. index(line, ", save,") == 0 .and. &
               index(line, "save ::") /= 1 .and. line /= "save", files(f)%s//": a module-level save variable: "//line)
            if (allocated(error)) return
            ! An initialised module variable is saved too. The one exception is volatile:
            ! the flag a signal handler sets (core/femcod_process), which has no other way
            ! to speak.
            if (.not. in_type .and. index(line, "::") > 0 .and. index(line, "=") > index(line, "::") .and. &
               index(line, "parameter") == 0 .and. index(line, "volatile") == 0 .and. index(line, "=>") == 0) then
               call check(error, .false., files(f)%s//": an initialised (saved) module variable: "//line)
               return
            end if
         end do
      end do
   end subroutine test_no_state

   !> The numerical layers (src/model, src/legacy, src/solvers) open, inquire, print and
   !> run nothing: no open, inquire(file=...), execute_command_line, no write or read on
   !> an external unit (internal writes into a character variable are text formatting);
   !> from core they use no file, process or /proc reader (femcod_files, femcod_process;
   !> of femcod_memory only memory_text, which formats a number). What the system says (the
   !> memory a run may use) comes in through the options.
   subroutine test_numerical_no_io(error)
      type(error_type), allocatable, intent(out) :: error
      type(string_type), allocatable :: files(:)
      character(len=:), allocatable :: text, line
      character(len=*), parameter :: FORBIDDEN(10) = [character(len=24) :: "open(", "open (", "inquire(file", &
         "execute_command_line", "write(output_unit", "write(error_unit", "write(*", "print *", "read(*", &
         "use femcod_files"]
      integer :: f, start, k, q
      files = sources()
      do f = 1, size(files)
         if (.not. (index(files(f)%s, "src/model/") == 1 .or. index(files(f)%s, "src/legacy/") == 1 .or. &
            index(files(f)%s, "src/solvers/") == 1)) cycle
         text = read_text(files(f)%s)
         start = 1
         do k = 1, len(text)
            if (text(k:k) /= new_line("a")) cycle
            line = lower_case(adjustl(text(start:k - 1)))
            start = k + 1
            if (index(line, "!") == 1) cycle
            do q = 1, size(FORBIDDEN)
               call check(error, .not. statement_starts(line, trim(FORBIDDEN(q))), files(f)%s// &
                  ": I/O in a numerical layer: "//line)
               if (allocated(error)) return
            end do
            call check(error, index(line, "use femcod_process") == 0, files(f)%s//": uses femcod_process")
            if (allocated(error)) return
            if (index(line, "use femcod_memory") == 1) then
               ! Only the formatting of byte counts (memory_text, usable_text), no reading.
               call check(error, trim(line) == "use femcod_memory, only: memory_text" .or. &
                  trim(line) == "use femcod_memory, only: memory_text, usable_text" .or. &
                  trim(line) == "use femcod_memory, only: usable_text", files(f)%s// &
                  ": reads the system's memory (pass it in the options): "//line)
               if (allocated(error)) return
            end if
         end do
      end do
   end subroutine test_numerical_no_io

   !> Whether `word` begins a statement of `line`: at its start, after a one-line if's
   !> condition (") "), or after "call " (a variable may be named like a keyword).
   pure logical function statement_starts(line, word)
      character(len=*), intent(in) :: line, word
      integer :: at
      at = index(line, word)
      statement_starts = at == 1
      if (at > 2) statement_starts = line(at - 2:at - 1) == ") "
      if (at > 5) statement_starts = statement_starts .or. line(at - 5:at - 1) == "call "
   end function statement_starts

   !> Every routine of src/, mpi/ and app/ at most MAX_ROUTINE_LINES long, but those of
   !> LONG_ROUTINES, each of which must still be longer (a stale entry fails too).
   subroutine test_routine_length(error)
      type(error_type), allocatable, intent(out) :: error
      type(string_type), allocatable :: files(:), names(:)
      integer, allocatable :: lengths(:)
      integer :: f, r, k
      logical :: listed, seen(size(LONG_ROUTINES))
      files = sources(programs=.true.)
      seen = .false.
      do f = 1, size(files)
         call routine_lengths(read_text(files(f)%s), names, lengths)
         do r = 1, size(names)
            listed = .false.
            do k = 1, size(LONG_ROUTINES)
               if (trim(LONG_ROUTINES(k)) == files(f)%s//" "//names(r)%s) then
                  listed = .true.
                  seen(k) = .true.
                  call check(error, lengths(r) > MAX_ROUTINE_LINES, files(f)%s//" "//names(r)%s//" is "// &
                     to_string(lengths(r))//" lines now: take it off LONG_ROUTINES")
                  if (allocated(error)) return
               end if
            end do
            if (.not. listed) call check(error, lengths(r) <= MAX_ROUTINE_LINES, files(f)%s//" "//names(r)%s//": "// &
               to_string(lengths(r))//" lines, above "//to_string(MAX_ROUTINE_LINES))
            if (allocated(error)) return
         end do
      end do
      do k = 1, size(LONG_ROUTINES)
         call check(error, seen(k), trim(LONG_ROUTINES(k))//": no such routine (take it off LONG_ROUTINES)")
         if (allocated(error)) return
      end do
   end subroutine test_routine_length

   !> The subroutines and functions of a source text, each with its length in lines from
   !> its first statement to its end statement (contained procedures counted in their
   !> host too). Comment lines are skipped; a procedure starts on a line whose first words
   !> are prefixes or a type followed by "subroutine NAME" or "function NAME".
   subroutine routine_lengths(text, names, lengths)
      character(len=*), intent(in) :: text
      type(string_type), allocatable, intent(out) :: names(:)
      integer, allocatable, intent(out) :: lengths(:)
      type(string_type) :: open_names(32)
      integer :: open_lines(32), depth, start, k, line_no
      character(len=:), allocatable :: line, word
      allocate(names(0), lengths(0))
      depth = 0
      start = 1
      line_no = 0
      do k = 1, len(text)
         if (text(k:k) /= new_line("a")) cycle
         line = lower_case(adjustl(text(start:k - 1)))
         start = k + 1
         line_no = line_no + 1
         if (index(line, "!") == 1) cycle
         if (index(line, "end subroutine") == 1 .or. index(line, "end function") == 1) then
            if (depth > 0) then
               names = [names, open_names(depth)]
               lengths = [lengths, line_no - open_lines(depth) + 1]
               depth = depth - 1
            end if
            cycle
         end if
         word = procedure_name(line)
         if (len(word) == 0 .or. depth == size(open_lines)) cycle
         depth = depth + 1
         open_names(depth)%s = word
         open_lines(depth) = line_no
      end do
   end subroutine routine_lengths

   !> NAME when `line` opens a procedure ("[prefixes] [type] subroutine|function NAME"),
   !> else "".
   function procedure_name(line) result(name)
      character(len=*), intent(in) :: line
      character(len=:), allocatable :: name
      character(len=:), allocatable :: rest
      integer :: at, e
      name = ""
      if (index(line, "end ") == 1 .or. index(line, "module procedure") == 1 .or. index(line, "procedure") == 1) &
         return
      at = index(line, "subroutine ")
      if (at == 0) at = index(line, "function ")
      if (at == 0) return
      ! Only prefixes, a type and a kind may come before the keyword.
      if (at > 1) then
         if (verify(line(1:at - 1), "abcdefghijklmnopqrstuvwxyz0123456789_(),:= *") /= 0) return
         if (index(line(1:at - 1), "=") > 0 .or. index(line(1:at - 1), "::") > 0 .or. &
            index(line(1:at - 1), "call") > 0) return
      end if
      rest = adjustl(line(at + index(line(at:), " "):))
      e = scan(rest, " (!")
      if (e > 0) rest = rest(1:e - 1)
      name = rest
   end function procedure_name
end module test_architecture
