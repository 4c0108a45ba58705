!> Issue 47: answers that were silently wrong. Each test failed on the main before its fix;
!> the expected values come from analysis of the scene (named in each test), not from a
!> run of femcod. The refusals of the same issue are cases of test/corpus/MANIFEST.
module test_silent
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_strings, only: string_type
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result, event_path_diagnostics, STOP_MAXCONT
   use femcod_solver_options, only: contact_options, SOLVER_INCREMENTAL, SOLVER_CG
   use femcod_solver, only: solve_contact, run_warnings
   use femcod_cli, only: run_femcod
   use test_support, only: scratch_path, file_exists, read_text
   use test_results, only: self_command
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_silent

contains

   subroutine collect_silent(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("a plastic run stopped by MAXCONT says so, and its check is finite", test_plastic_maxcont), &
         new_unittest("a state off contact has load 0; the load is the pressures' sum", test_load_is_the_map_sum), &
         new_unittest("a tangential step without contact is a warning", test_tangential_without_contact), &
         new_unittest("-o DIR/NAME makes DIR, as the README's first example needs", test_output_directory_made), &
         new_unittest("every solver gives the same bits on 1, 2 and 3 threads", test_thread_count)]
   end subroutine collect_silent

   !> README's example `run sphere_d1.deck --loads 1e4 --plastic --hardness 11` (MAXCONT
   !> 316). Before: the stop reason said "no further pixel can come into contact" and the
   !> final check "differs by -Inf" (a re-solve of an empty elastic set). Analysis: every
   !> one of the 316 pixels ends capped at H d^2 = 11 nN (d = 1 nm), so the path stops at
   !> 316 x 11 = 3476 nN with MAXCONT reached and nothing elastic left to re-solve.
   subroutine test_plastic_maxcont(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      type(string_type), allocatable :: lines(:)
      call read_deck("input/sphere_d1.deck", deck, status)
      options%solver = SOLVER_INCREMENTAL
      options%plastic = .true.
      options%hardness = 11
      options%loads = [1.0e4_dp]
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, res%stop_reason, STOP_MAXCONT, "the stop reason")
      if (allocated(error)) return
      call check(error, .not. res%states(1)%reached, "1e4 nN is beyond 316 capped pixels")
      if (allocated(error)) return
      call check(error, res%step_load(res%nsteps), 316*11.0_dp, thr=1.0e-12_dp, rel=.true., &
         message="the last step's load "//to_string(res%step_load(res%nsteps)))
      if (allocated(error)) return
      select type (d => res%diagnostics)
      class is (event_path_diagnostics)
         call check(error, d%final_check_difference, 0.0_dp, message="nothing elastic to re-solve")
         if (allocated(error)) return
      end select
      lines = run_warnings(options, res)
      call check(error, size(lines), 1, "one warning")
      if (allocated(error)) return
      call check(error, lines(1)%s == "load 1e4 nN not reached (maximum number of contacts reached)", lines(1)%s)
   end subroutine test_plastic_maxcont

   !> cg with the cap under displacement control, 2.5 nm then 1 nm into the 15 nm sphere of
   !> sphere_d1. Before: the 1 nm state reported 2.98e-12 nN (the iteration's residual)
   !> and a loaded state's load differed from its pressures' sum by 1e-7. Analysis: with
   !> the plastic displacement kept from 2.5 nm (the sphere's cap sank by its plastic
   !> displacement) no pixel touches at 1 nm, so the load is 0; and the load of a state is
   !> the sum of its contact forces, the pressure map times d^2.
   subroutine test_load_is_the_map_sum(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      call read_deck("input/sphere_d1.deck", deck, status)
      options%solver = SOLVER_CG
      options%plastic = .true.
      options%hardness = 11
      options%approaches = [2.5_dp, 1.0_dp]
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, res%states(1)%load, sum(res%states(1)%force), thr=1.0e-14_dp, rel=.true., &
         message="the load is the contact forces' sum")
      if (allocated(error)) return
      call check(error, res%states(2)%contacts, 0, "no contact at 1 nm after the plastic 2.5 nm")
      if (allocated(error)) return
      call check(error, res%states(2)%load == 0, "load "//to_string(res%states(2)%load)//" off contact, not 0")
   end subroutine test_load_is_the_map_sum

   !> The same path with a tangential force of 500 nN (mu = 0.3): before, the state
   !> without contact reported a tangential force 0 and stick fraction 0 with no warning.
   subroutine test_tangential_without_contact(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      type(string_type), allocatable :: lines(:)
      call read_deck("input/sphere_d1.deck", deck, status)
      options%solver = SOLVER_CG
      options%plastic = .true.
      options%hardness = 11
      options%approaches = [2.5_dp, 1.0_dp]
      options%tangential = .true.
      options%friction = 0.3_dp
      options%tangential_load = 500
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      call check(error, .not. allocated(res%states(2)%stick), "no tangential step without contact")
      if (allocated(error)) return
      lines = run_warnings(options, res)
      call check(error, size(lines), 1, "one warning")
      if (allocated(error)) return
      call check(error, index(lines(1)%s, "state 2 (approach 1 nm) has no contact") == 1, lines(1)%s)
   end subroutine test_tangential_without_contact

   !> README's `femcod run input/circle_punch_d9.deck --loads 1 -o out/circle` in a fresh
   !> directory. Before: exit 5, "out/circle.lock: cannot write the lock file".
   subroutine test_output_directory_made(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir
      integer :: code
      dir = scratch_path("silent_outdir")
      call execute_command_line("rm -rf "//dir)
      call run_femcod([string_type("run"), string_type("input/circle_punch_d9.deck"), string_type("--loads"), &
         string_type("1"), string_type("-o"), string_type(dir//"/out/circle"), string_type("--quiet")], code)
      call check(error, code, 0, "exit code")
      if (allocated(error)) return
      call check(error, file_exists(dir//"/out/circle.h5") .and. file_exists(dir//"/out/circle.loads.csv"), &
         "the results in the directory made for them")
   end subroutine test_output_directory_made

   !> Issue 47, section 7: cg at 1e5 nN on a 128^2 deck gave approach ...3974 on 2
   !> threads and ...3871 on 1 (OpenMP's reductions add the threads' shares in an order
   !> that follows the split; OpenBLAS blocks its factorisations by its threads, which
   !> follow OMP_NUM_THREADS). Every path of every solver, run as a user runs it, must
   !> write the same PREFIX.loads.csv (17 significant digits) on 1, 2 and 3 threads.
   subroutine test_thread_count(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, rough, reference, args
      character(len=*), parameter :: SPHERE = "input/sphere_d1.deck"
      character(len=120), parameter :: PATHS(8) = [character(len=120) :: &
         "--solver cg --loads 1e4,2e5", &
         "--solver cg --boundary periodic --loads 1e4,2e5", &
         "--solver cg --plastic --hardness 5 --approach 2,4,3", &
         "--solver cg --adhesion exponential --work 0.05 --range 1 --approach 1,3,-1", &
         "--solver incremental --loads 1e3,1e4 --plastic --hardness 8", &
         "--solver cg --loads 1e4 --tangential 1000 --friction 0.3", &
         "SPHERE --solver legacy --loads 300,1000", &
         "SPHERE --solver cg --loads 3000 --shear-strength 0.1 --shear-slope 0.05"]
      integer :: k, threads, code
      dir = scratch_path("threads")
      rough = dir//"/rough.deck"
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call run_femcod([string_type("mkdeck"), string_type("self-affine"), string_type("--np"), string_type("64"), &
         string_type("--pixel"), string_type("5"), string_type("--rms"), string_type("3"), string_type("--seed"), &
         string_type("3"), string_type("--shape-on"), string_type("lower"), string_type("-o"), string_type(rough)], code)
      call check(error, code, 0, "mkdeck")
      if (allocated(error)) return
      do k = 1, size(PATHS)
         args = trim(PATHS(k))
         if (index(args, "SPHERE") == 1) then
            args = SPHERE//args(7:)
         else
            args = rough//" "//args
         end if
         do threads = 1, 3
            call execute_command_line("OMP_NUM_THREADS="//to_string(threads)//" "//self_command()//" run "//args// &
               " -o "//dir//"/t"//to_string(threads)//" --quiet --force > /dev/null 2>&1", exitstat=code)
            call check(error, code, 0, "femcod run "//args//" on "//to_string(threads)//" threads")
            if (allocated(error)) return
            if (threads == 1) then
               reference = read_text(dir//"/t1.loads.csv")
            else
               call check(error, read_text(dir//"/t"//to_string(threads)//".loads.csv") == reference, &
                  "femcod run "//args//": "//to_string(threads)//" threads differ from 1")
               if (allocated(error)) return
            end if
         end do
      end do
   end subroutine test_thread_count
end module test_silent
