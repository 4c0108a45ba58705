!> The shape of src/ (doc/architecture.md): the layers core < model < legacy < solvers <
!> io < studies < cli, each a folder; a module uses only its own layer and those below.
!> femcod-mpi's modules (mpi/src, built apart with MPI) are one more layer on top.
!> The numerical core keeps no state between calls (no module-level save variables) and
!> never stops the program.
module test_architecture
   use femcod_strings, only: string_type
   use test_support, only: scratch_path, read_text
   use testdrive, only: new_unittest, unittest_type, error_type, check
   implicit none
   private
   public :: collect_architecture

   character(len=*), parameter :: LAYERS(8) = [character(len=7) :: "core", "model", "legacy", "solvers", "io", &
      "studies", "cli", "mpi"]

contains

   subroutine collect_architecture(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("every use points to the same layer or one below", test_layers), &
         new_unittest("no module-level save variables, no stop in src/", test_no_state) &
         ]
   end subroutine collect_architecture

   !> The source files under src/ and mpi/src/ (one per line), from `find`.
   function sources() result(files)
      type(string_type), allocatable :: files(:)
      character(len=:), allocatable :: list, text
      integer :: start, k
      list = scratch_path("sources.txt")
      call execute_command_line("find src mpi/src -name '*.[fF]90' | sort > "//list)
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
      if (index(path, "mpi/src/") == 1) layer_of = size(LAYERS)
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
         line = lower(adjustl(text(start:k - 1)))
         start = k + 1
         if (index(line, keyword//" ") /= 1) cycle
         word = adjustl(line(len(keyword) + 2:))
         e = scan(word, " ,!")
         if (e > 0) word = word(1:e - 1)
         if (keyword == "module" .and. (word == "procedure" .or. word == "function" .or. word == "subroutine")) cycle
         names = [names, string_type(word)]
      end do
   end subroutine statements

   pure function lower(s) result(t)
      character(len=*), intent(in) :: s
      character(len=len(s)) :: t
      integer :: k
      t = s
      do k = 1, len(s)
         if (s(k:k) >= "A" .and. s(k:k) <= "Z") t(k:k) = achar(iachar(s(k:k)) + 32)
      end do
   end function lower

   subroutine test_layers(error)
      type(error_type), allocatable, intent(out) :: error
      type(string_type), allocatable :: files(:), mods(:), uses(:), module_name(:)
      integer, allocatable :: module_layer(:)
      character(len=:), allocatable :: text
      integer :: f, u, m, found
      files = sources()
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
            line = lower(adjustl(text(start:k - 1)))
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
end module test_architecture
