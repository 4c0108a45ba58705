!> What the benchmarks share: their option parsing, the benchmark surface (self-affine, 5 um),
!> the peers' script and its output, a table row, the peak memory.
!> Benchmarks only measure: nothing numerical lives in app/ (doc/performance.md).
module femcod_bench_common
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_problem, only: contact_problem
   use femcod_generate, only: scene_spec, build_problem
   use femcod_contact_result, only: contact_result
   use femcod_strings, only: string_type, int_str, real_str, fixed_str
   use femcod_options, only: option_spec, parsed_options, parse_options
   use femcod_analytic, only: segedin_sphere
   use femcod_scene, only: initial_gaps
   use femcod_files, only: path_exists, canonical_path, path_is_directory, make_directories
   use femcod_solver_options, only: contact_options, validate_options, requested_states
   use femcod_output_guard, only: guard_outputs
   use femcod_convolution, only: transform_pair, transform_pair_setup, transform_pair_apply, transform_pair_free
   use femcod_clock, only: wall_clock
   implicit none
   private
   public :: bare_pair_seconds
   public :: bench_arguments, bad_arguments, benchmark_surface, linear_law, self_path, peers_script, require_peers, &
      require_program, prepare_directory, guard_bench_files, options_refused, surface_for_peers, &
      json_value, read_text_file, write_peer_gaps, remove_file_quietly, peer_line, peer_row, row, segedin, &
      reset_peak, peak_mb, BENCH_LENGTH

   !> The benchmark surface's side: 5 um.
   real(dp), parameter :: BENCH_LENGTH = 5000

contains

   !> The message of a failed parse, or of an argument the bench takes no positional for.
   !> Parse a bench command's arguments against its option table; false, with the
   !> message on standard error, when they do not fit it (or a positional is given).
   logical function bench_arguments(table, args, command, parsed) result(ok)
      type(option_spec), intent(in) :: table(:)
      type(string_type), intent(in) :: args(:)
      character(len=*), intent(in) :: command
      type(parsed_options), intent(out) :: parsed
      type(status_type) :: status
      call parse_options(table, args, parsed, status)
      if (status%code == 0 .and. size(parsed%positional) > 0) status%code = 2
      ok = status%code == 0
      if (.not. ok) write(error_unit, '(a)') command//": "//bad_arguments(status, parsed)//" ("// &
         trim(merge("femcod bench --help", "--help             ", command == "femcod bench"))//")"
   end function bench_arguments

   !> The benchmark's solver options checked as `femcod run` checks its own
   !> (validate_options), before any surface is made or file read: a refused combination
   !> is reported as `command: message` (the caller exits 2). One load stands in for the
   !> benchmark's, which it computes case by case.
   logical function options_refused(options, command) result(refused)
      type(contact_options), intent(in) :: options
      character(len=*), intent(in) :: command
      type(contact_options) :: probe
      type(status_type) :: status
      probe = options
      if (requested_states(probe) == 0) probe%loads = [1.0_dp]
      call validate_options(probe, status)
      refused = status%code /= 0
      if (refused) write(error_unit, '(a)') command//": "//status%message
   end function options_refused

   function bad_arguments(status, parsed) result(text)
      type(status_type), intent(in) :: status
      type(parsed_options), intent(in) :: parsed
      character(len=:), allocatable :: text
      if (allocated(status%message)) then
         text = status%message
      else
         text = "unknown argument "//parsed%positional(1)%s
      end if
   end function bad_arguments

   !> The benchmark surface of every table: self-affine, Hurst 0.8, rms 3 nm, 5 um square,
   !> NP x NP, E = 200 GPa, nu = 0.25, on the lower body against a rigid flat (seed 1).
   subroutine benchmark_surface(np, label, deck, status)
      integer, intent(in) :: np
      character(len=*), intent(in) :: label
      type(contact_problem), intent(out) :: deck
      type(status_type), intent(inout) :: status
      type(scene_spec) :: spec
      spec%kind = "self-affine"
      spec%np = np
      spec%pixel = BENCH_LENGTH/np
      spec%hurst = 0.8_dp
      spec%rms = 3
      spec%seed = 1
      spec%shape_on = "lower"
      spec%rigid = "upper"
      spec%label = label
      spec%matrix_file = ""
      spec%maxcont = 1
      call build_problem(spec, deck, status)
   end subroutine benchmark_surface

   !> The benchmark surface at NP (benchmark_surface) and its linear law (E*, the rms
   !> slope); with peers (`python` not empty) its gaps written to `path` for them to read
   !> (the peers solve from the file: the bench keeps no copy of the gaps).
   subroutine surface_for_peers(np, label, python, deck, estar, slope, path, status)
      integer, intent(in) :: np
      character(len=*), intent(in) :: label, python
      type(contact_problem), intent(out) :: deck
      real(dp), intent(out) :: estar, slope
      character(len=:), allocatable, intent(out) :: path
      type(status_type), intent(inout) :: status
      real(dp), allocatable :: g0(:, :)
      path = "femcod-bench-gaps.f64"
      call benchmark_surface(np, label, deck, status)
      if (status%code /= 0) return
      call linear_law(deck, estar, slope, g0)
      if (len(python) > 0) call write_peer_gaps(path, g0)
   end subroutine surface_for_peers

   !> What the linear law of contact area needs: the composite modulus E* of the
   !> solver's model (elastic body on a rigid one) and the rms slope of the gaps; the
   !> mean pressure for a contact fraction f is f E* slope / 2 (kappa = 2).
   subroutine linear_law(deck, estar, slope, g0)
      type(contact_problem), intent(in) :: deck
      real(dp), intent(out) :: estar, slope
      real(dp), allocatable, intent(out) :: g0(:, :)
      integer :: np
      np = deck%np
      estar = 1/(1/(deck%young(1)/(1 - deck%poisson(1)**2)) + 1/(deck%young(2)/(1 - deck%poisson(2)**2)))
      g0 = transpose(reshape(initial_gaps(deck%lower, deck%upper), [np, np]))
      slope = sqrt((sum((g0(2:, :) - g0(:np - 1, :))**2) + sum((g0(:, 2:) - g0(:, :np - 1))**2)) &
         /(np*(np - 1.0_dp)))/deck%pixel
   end subroutine linear_law

   !> This program's path (argument 0).
   function self_path() result(path)
      character(len=:), allocatable :: path
      integer :: length
      call get_command_argument(0, length=length)
      allocate(character(len=length) :: path)
      call get_command_argument(0, path)
   end function self_path

   !> The peers' script: app/femcod_peers.py of the source tree (run from its root), or
   !> the copy `setup.sh` installs beside femcod (PREFIX/share/femcod/femcod_peers.py for
   !> PREFIX/bin/femcod); "" when neither exists.
   function peers_script() result(path)
      character(len=:), allocatable :: path, exe
      integer :: slash
      path = "app/femcod_peers.py"
      if (path_exists(path)) return
      exe = canonical_path("/proc/self/exe")
      slash = index(exe, "/", back=.true.)
      path = ""
      if (slash > 1) then
         path = exe(1:slash - 1)//"/../share/femcod/femcod_peers.py"
         if (.not. path_exists(path)) path = ""
      end if
   end function peers_script

   !> With --peers PYTHON, the peers' script must be found before any work (exit 2).
   subroutine require_peers(python, command, code)
      character(len=*), intent(in) :: python, command
      integer, intent(inout) :: code
      if (len(python) == 0 .or. code /= 0) return
      call require_program("--peers", python, command, code)
      if (code /= 0) return
      if (len(peers_script()) > 0) return
      write(error_unit, '(a)') "femcod bench "//command//": --peers needs femcod_peers.py: app/femcod_peers.py "// &
         "of the source tree (run from its root) or the copy setup.sh installs in PREFIX/share/femcod; found neither"
      code = 2
   end subroutine require_peers

   !> A program an option names (its first word, for a launcher with options) must be
   !> there before any work: a path to an executable file, or a name on PATH (exit 2).
   subroutine require_program(option, program, command, code)
      character(len=*), intent(in) :: option, program, command
      integer, intent(inout) :: code
      character(len=:), allocatable :: first
      integer :: blank, found, launched
      if (code /= 0) return
      first = trim(adjustl(program))
      blank = index(first, " ")
      if (blank > 0) first = first(1:blank - 1)
      found = 1
      if (len(first) > 0 .and. scan(first, "'") == 0) &
         call execute_command_line("p=$(command -v '"//first//"' 2> /dev/null) && test -f ""$p"" && "// &
            "test -x ""$p"" || exit 1", exitstat=found, cmdstat=launched)
      if (found == 0) return
      write(error_unit, '(a)') "femcod bench "//command//": "//option//" "//program//": no such program ("//first// &
         " is not an executable file and not on PATH)"
      code = 2
   end subroutine require_program

   !> The directory a bench writes into (`--dir`), made before any work: a name that is a
   !> file is refused (exit 2), a directory that cannot be made is an I/O error (exit 5).
   subroutine prepare_directory(dir, command, code)
      character(len=*), intent(in) :: dir, command
      integer, intent(inout) :: code
      type(status_type) :: status
      if (code /= 0) return
      if (path_exists(dir) .and. .not. path_is_directory(dir)) then
         write(error_unit, '(a)') "femcod bench "//command//": --dir "//dir//": exists and is not a directory"
         code = 2
         return
      end if
      ! femcod_files' make_directories: the OS's reason when a part cannot be made.
      call make_directories(dir, status)
      if (status%code == 0) return
      write(error_unit, '(a)') "femcod bench "//command//": --dir "//status%message
      code = status%code
   end subroutine prepare_directory

   !> The files a bench is about to write (each of kind `kind`, OUTPUT_* of
   !> femcod_output_guard) replace only what femcod wrote: a user's file of that name is
   !> left as it is (exit 5), a directory of that name refused (exit 2). A bench reruns
   !> over its own files without --force, as it always has.
   subroutine guard_bench_files(names, kind, command, code)
      type(string_type), intent(in) :: names(:)
      integer, intent(in) :: kind
      character(len=*), intent(in) :: command
      integer, intent(inout) :: code
      type(status_type) :: status
      type(string_type), allocatable :: none(:)
      if (code /= 0) return
      allocate(none(0))
      call guard_outputs(names, none, .true., kind, status)
      if (status%code == 0) return
      write(error_unit, '(a)') "femcod bench "//command//": "//status%message
      code = status%code
   end subroutine guard_bench_files

   !> The number after `"key": ` in the JSON text (its first occurrence; 0 when absent).
   real(dp) function json_value(t, key)
      character(len=*), intent(in) :: t, key
      integer :: at, ends, ios2
      json_value = 0
      at = index(t, key//": ")
      if (at == 0) return
      at = at + len(key) + 2
      ends = scan(t(at:), ",}"//new_line("a"))
      if (ends == 0) return
      read(t(at:at + ends - 2), *, iostat=ios2) json_value
      if (ios2 /= 0) json_value = 0
   end function json_value

   function read_text_file(path) result(t)
      character(len=*), intent(in) :: path
      character(len=:), allocatable :: t
      integer :: unit, size_bytes, ios2
      open(newunit=unit, file=path, access="stream", form="unformatted", action="read", status="old", iostat=ios2)
      if (ios2 /= 0) then
         t = ""
         return
      end if
      inquire(unit=unit, size=size_bytes)
      allocate(character(len=size_bytes) :: t)
      read(unit, iostat=ios2) t
      close(unit)
   end function read_text_file

   !> One table row from the peer script's line "peer seconds iterations residual fraction
   !> peak status" (fraction as a share, printed in percent).
   !> The gaps (nm) for the peers, NP*NP float64 in Fortran order (app/femcod_peers.py).
   subroutine write_peer_gaps(path, g0)
      character(len=*), intent(in) :: path
      real(dp), intent(in) :: g0(:, :)
      integer :: unit
      open(newunit=unit, file=path, access="stream", form="unformatted", status="replace", action="write")
      write(unit) g0
      close(unit)
   end subroutine write_peer_gaps

   subroutine remove_file_quietly(path)
      character(len=*), intent(in) :: path
      integer :: unit, ios
      open(newunit=unit, file=path, status="old", iostat=ios)
      if (ios == 0) close(unit, status="delete")
   end subroutine remove_file_quietly

   !> One peer's answer line (app/femcod_peers.py) on the gaps in `path`, or
   !> "PEER - - - - - failed -" when it gave none.
   function peer_line(python, peer, path, np, pixel, estar, pressure, tol, extra) result(line)
      character(len=*), intent(in) :: python, peer, path
      integer, intent(in) :: np
      real(dp), intent(in) :: pixel, estar, pressure, tol
      !> More arguments for the peer (tamaas-adhesion: LAW W RANGE).
      character(len=*), intent(in), optional :: extra
      character(len=512) :: line
      character(len=:), allocatable :: more
      character(len=*), parameter :: peer_out = "femcod-bench-peer.txt"
      integer :: unit, ios
      more = ""
      if (present(extra)) more = " "//extra
      call execute_command_line(python//" "//peers_script()//" "//peer//" "//path//" "//int_str(np)//" "// &
         real_str(pixel, 16)//" "//real_str(estar, 16)//" "//real_str(pressure, 16)//" "//real_str(tol, 3)// &
         more//" > "//peer_out, exitstat=ios)
      line = peer//" - - - - - failed -"
      open(newunit=unit, file=peer_out, action="read", status="old", iostat=ios)
      if (ios == 0) then
         read(unit, '(a)', iostat=ios) line
         close(unit, status="delete")
      end if
   end function peer_line

   subroutine peer_row(np, target, line)
      integer, intent(in) :: np
      real(dp), intent(in) :: target
      character(len=*), intent(in) :: line
      character(len=64) :: words(7)
      real(dp) :: fraction
      integer :: ios
      words = "-"
      read(line, *, iostat=ios) words
      read(words(5), *, iostat=ios) fraction
      if (ios == 0) words(5) = fixed_str(100*fraction, 2)
      write(output_unit, '(a)') "| "//int_str(np)//" | "//fixed_str(target, 1)//" | "//trim(words(1))//" | "// &
         trim(words(2))//" | "//trim(words(3))//" | "//trim(words(4))//" | "//trim(words(5))//" | "// &
         trim(words(6))//" | "//trim(words(7))//" |"
      flush(output_unit)
   end subroutine peer_row

   subroutine row(problem, np, res, solver, error, reference, peak)
      character(len=*), intent(in) :: problem, solver, reference
      integer, intent(in) :: np
      type(contact_result), intent(in) :: res
      real(dp), intent(in) :: error, peak
      integer :: contacts
      contacts = size(res%contact_i)
      write(output_unit, '(a)') "| "//problem//" | "//int_str(np)//" | "//int_str(contacts)//" | "//solver//" | "// &
         real_str(res%wall_seconds, 3)//" | "//real_str(1000*res%wall_seconds/max(res%nsteps, 1), 3)//" | "// &
         real_str(peak, 3)//" | "//real_str(error, 2)//" | "//reference//" |"
      flush(output_unit)
   end subroutine row

   !> Segedin's rigid sphere R = 15 nm on E = 200 GPa, nu = 0.25: approach at load f.
   real(dp) function segedin(f)
      real(dp), intent(in) :: f
      real(dp) :: a
      call segedin_sphere(f, 15.0_dp, 200/(1 - 0.25_dp**2), a, segedin)
   end function segedin

   !> Reset the kernel's peak-RSS counter of this process (Linux /proc/self/clear_refs).
   subroutine reset_peak()
      integer :: unit, ios
      open(newunit=unit, file="/proc/self/clear_refs", action="write", iostat=ios)
      if (ios == 0) then
         write(unit, '(a)', iostat=ios) "5"
         close(unit, iostat=ios)
      end if
   end subroutine reset_peak

   !> Peak resident memory (MB) since the last reset, from /proc/self/status (VmHWM).
   real(dp) function peak_mb()
      integer :: unit, ios, kb
      character(len=256) :: line
      peak_mb = -1
      open(newunit=unit, file="/proc/self/status", action="read", iostat=ios)
      if (ios /= 0) return
      do
         read(unit, '(a)', iostat=ios) line
         if (ios /= 0) exit
         if (line(1:6) == "VmHWM:") then
            read(line(7:), *, iostat=ios) kb
            if (ios == 0) peak_mb = kb/1024.0_dp
            exit
         end if
      end do
      close(unit)
   end function peak_mb

   !> Seconds per bare pair of FFTs on M x M (femcod_convolution's transform_pair: FFTW's
   !> threaded 2-D r2c and c2r in double), the yardstick of a convolution: the mean of
   !> `repeat` after one untimed, with FFTW_MEASURE plans when `measure`, else
   !> FFTW_ESTIMATE; the planning is not timed.
   real(dp) function bare_pair_seconds(m, measure, repeat) result(seconds)
      integer, intent(in) :: m, repeat
      logical, intent(in) :: measure
      type(transform_pair) :: pair
      real(dp) :: t0, t1
      integer :: k
      call transform_pair_setup(pair, m, measure)
      call transform_pair_apply(pair)
      call wall_clock(t0)
      do k = 1, repeat
         call transform_pair_apply(pair)
      end do
      call wall_clock(t1)
      seconds = (t1 - t0)/repeat
      call transform_pair_free(pair)
   end function bare_pair_seconds
end module femcod_bench_common
