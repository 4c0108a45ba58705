!> The combination matrix (issue 34): every solver x boundary x plastic cap x interface
!> law x way of asking (loads, increasing approaches, decreasing approaches) x (plain,
!> restart, friction from the pressures: --shear-strength 0 --shear-slope 0.1 (with
!> --figures none, which writes no pressure figure and changes nothing else), a
!> tangential step: --friction 0.3 --tangential 10 --tangential-tol 1e-10, the Love
!> kernel cut beyond the grid: --kernel-radius 30 on the 15 x 15 grid, whose offsets
!> reach 14 sqrt 2 = 19.8), run
!> as a user runs it (this test executable as femcod, in its own process) on the thesis'
!> 2 nm sphere (input/sphere_d2.deck, 15 x 15 pixels). Each combination either answers
!> (exit 0, one row of PREFIX.loads.csv per state asked) or is refused (exit 2) with no
!> output and no lock; none ends in a runtime error or a backtrace. Where two solvers
!> answer the same question, they agree: the event-exact solvers (incremental, legacy)
!> to 1e-9 of each other, cg (run at --tol 1e-10) to 1e-6 of them, in the load of an
!> approach or the approach of a load. The reference is the other solver: the three are
!> independent algorithms (Appendix B's skyline factor, a bordered Cholesky factor of the
!> contact set, constrained conjugate gradients). With the shear model (a sum over the
!> answer, no solve) a combination is refused exactly where it is without (and with
!> --adhesion), and answers the same, with friction_coefficient = 0.1 = alpha, since
!> tau0 = 0 and the forces balance the load (to 1e-6: the legacy solver's forces carry
!> its skyline factor's condition times eps; 1.6e-11 measured here). With the tangential
!> step (refused with adhesion, as the shear model) the normal answer is the same too, and the tangential force of every
!> state is Q = 10 nN (the multiplier's Newton solve holds sum t = Q to 1e-14 mu P).
!> With --kernel-radius beyond the grid (cg only: the other solvers refuse it) the table
!> is whole, so every cg path of the free surface, the fixed-load and the gap variables,
!> answers exactly as without it, bit for bit, and refuses exactly where it does; on the
!> periodic cell it is refused (issue 47: a cut periodic kernel changes the cell's mean
!> compliance, -28 % in the approach at R = 16 on a 32-pixel cell).
module test_matrix
   use femcod_kinds, only: dp
   use test_support, only: scratch_path, read_text, file_exists, contains_text
   use test_results, only: self_command, csv_column, csv_named_column
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_matrix

   character(len=*), parameter :: SOLVERS(3) = [character(len=11) :: "incremental", "legacy", "cg"]
   character(len=*), parameter :: BOUNDARIES(2) = [character(len=8) :: "free", "periodic"]
   character(len=*), parameter :: LAWS(3) = [character(len=11) :: "none", "dugdale", "exponential"]
   character(len=*), parameter :: MODES(3) = [character(len=10) :: "loads", "increasing", "decreasing"]

contains

   subroutine collect_matrix(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [new_unittest("every combination answers or is refused (exit 2), and the answers agree", &
         test_matrix_run)]
   end subroutine collect_matrix

   subroutine test_matrix_run(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, args, prefix, stderr, listing
      ! answers(solver, boundary, plastic, law, mode): the values of the first and second state
      real(dp) :: answers(2, 3, 2, 2, 3, 3)
      logical :: answered(3, 2, 2, 3, 3)
      real(dp), allocatable :: column(:), contacts(:)
      integer :: s, b, p, l, m, r, code, n, refused, combos, k
      dir = scratch_path("matrix")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      answered = .false.
      refused = 0
      combos = 0
      n = 0
      do s = 1, size(SOLVERS)
         do b = 1, size(BOUNDARIES)
            do p = 1, 2
               do l = 1, size(LAWS)
                  do m = 1, size(MODES)
                     do r = 1, 5
                        n = n + 1
                        combos = combos + 1
                        prefix = dir//"/c"//to_string(n)
                        args = "run input/sphere_d2.deck -o "//prefix//" --quiet --solver "//trim(SOLVERS(s))// &
                           " --boundary "//trim(BOUNDARIES(b))//question(m)
                        if (SOLVERS(s) == "cg") args = args//" --tol 1e-10 --max-iterations 20000"
                        if (p == 2) args = args//" --plastic --hardness 11"
                        if (LAWS(l) /= "none") args = args//" --adhesion "//trim(LAWS(l))//" --work 0.05 --range 1"
                        if (r == 2) args = args//" --restart"
                        if (r == 3) args = args//" --shear-strength 0 --shear-slope 0.1 --figures none"
                        if (r == 4) args = args//" --friction 0.3 --tangential 10 --tangential-tol 1e-10"
                        if (r == 5) args = args//" --kernel-radius 30"
                        call execute_command_line(self_command()//" "//args//" > "//prefix//".out 2> "//prefix// &
                           ".err", exitstat=code)
                        stderr = read_text(prefix//".err")
                        call check(error, code == 0 .or. code == 2, "femcod "//args//": exit "//to_string(code)// &
                           ", neither an answer nor a refusal: "//stderr)
                        if (allocated(error)) return
                        call check(error, .not. (contains_text(stderr, "Backtrace") .or. &
                           contains_text(stderr, "runtime error") .or. contains_text(stderr, "Error termination")), &
                           "femcod "//args//": a runtime error: "//stderr)
                        if (allocated(error)) return
                        call check(error, .not. file_exists(prefix//".lock"), "femcod "//args//": a lock left behind")
                        if (allocated(error)) return
                        if (r == 5) then
                           call check(error, (code == 0) .eqv. (SOLVERS(s) == "cg" .and. BOUNDARIES(b) == "free" &
                              .and. answered(s, b, p, l, m)), "femcod "//args//": --kernel-radius beyond the grid "// &
                              "answers only where cg does without it, and on the free surface only")
                           if (allocated(error)) return
                        end if
                        if ((r == 3 .or. r == 4) .and. LAWS(l) == "none") then
                           call check(error, (code == 2) .eqv. .not. answered(s, b, p, l, m), "femcod "//args// &
                              ": the friction options changed whether the combination is answered")
                           if (allocated(error)) return
                        end if
                        if (code == 2) then
                           refused = refused + 1
                           listing = outputs_of(prefix)
                           call check(error, listing == "", "femcod "//args//": refused, but wrote "//listing)
                           if (allocated(error)) return
                           call check(error, len_trim(stderr) > 0, "femcod "//args//": refused without a word")
                           if (allocated(error)) return
                           cycle
                        end if
                        column = csv_column(prefix//".loads.csv", merge(2, 1, m == 1))
                        call check(error, size(column), 2, "femcod "//args//": one row per state asked")
                        if (allocated(error)) return
                        if (m == 3) column = column(2:1:-1)
                        if (r == 1) then
                           answers(:, s, b, p, l, m) = column
                           answered(s, b, p, l, m) = .true.
                        else if (r == 4) then
                           call check(error, all(column == answers(:, s, b, p, l, m)), "femcod "//args// &
                              ": the tangential step changed the normal answer")
                           if (allocated(error)) return
                           column = csv_named_column(prefix//".loads.csv", "tangential_force_nN")
                           contacts = csv_named_column(prefix//".loads.csv", "contacts")
                           ! A state without contact (unloaded off it) carries no tangential force.
                           where (contacts == 0) column = 10
                           call check(error, all(abs(column - 10) <= 1.0e-12_dp*10), "femcod "//args// &
                              ": tangential forces "//to_string(column(1))//", "//to_string(column(2))//", not Q = 10")
                           if (allocated(error)) return
                        else if (r == 5) then
                           call check(error, all(column == answers(:, s, b, p, l, m)), "femcod "//args// &
                              ": a kernel cut beyond the grid changed the answer")
                           if (allocated(error)) return
                        else if (r == 3) then
                           call check(error, all(column == answers(:, s, b, p, l, m)), "femcod "//args// &
                              ": the shear model changed the answer")
                           if (allocated(error)) return
                           call check(error, .not. (file_exists(prefix//".pressure_1.svg") .or. &
                              file_exists(prefix//".pressure_2.svg")), "femcod "//args//": --figures none wrote a figure")
                           if (allocated(error)) return
                           column = csv_named_column(prefix//".loads.csv", "friction_coefficient")
                           contacts = csv_named_column(prefix//".loads.csv", "contacts")
                           do k = 1, size(column)
                              ! No contact (unloaded off it): no coefficient, nan.
                              if (contacts(k) == 0) then
                                 call check(error, column(k) /= column(k), "femcod "//args// &
                                    ": a friction coefficient without contact")
                                 if (allocated(error)) return
                                 cycle
                              end if
                              call check(error, abs(column(k) - 0.1_dp) <= 1.0e-6_dp, "femcod "//args// &
                                 ": friction_coefficient "//to_string(column(k))//", not alpha = 0.1")
                              if (allocated(error)) return
                           end do
                        else if (answered(s, b, p, l, m)) then
                           ! A restart without a checkpoint is a fresh run: the same answer.
                           call check(error, all(column == answers(:, s, b, p, l, m)), "femcod "//args// &
                              ": --restart without a checkpoint differs from the run without it")
                           if (allocated(error)) return
                        end if
                     end do
                  end do
               end do
            end do
         end do
      end do
      call agreement(error)
      if (allocated(error)) return
      ! The matrix is not all refusals: each solver answers some of it, and cg the most.
      call check(error, any(answered(1, :, :, :, :)) .and. any(answered(2, :, :, :, :)) .and. &
         count(answered(3, :, :, :, :)) > count(answered(2, :, :, :, :)), "every solver answers somewhere")
      if (allocated(error)) return
      write(*, '(a)') "           matrix: "//to_string(combos)//" combinations, "//to_string(refused)// &
         " refused (exit 2), "//to_string(combos - refused)//" answered"
   contains
      !> The arguments that ask the question of mode m: two loads (nN) or two approaches
      !> (nm) in increasing or decreasing order.
      function question(mode) result(text)
         integer, intent(in) :: mode
         character(len=:), allocatable :: text
         select case (mode)
         case (1)
            text = " --loads 300,800"
         case (2)
            text = " --approach 0.5,1"
         case default
            text = " --approach 1,0.5"
         end select
      end function question

      !> Solvers that answered the same question agree (the event solvers to 1e-9, cg to
      !> 1e-6). Approach answers of load questions are compared against the sphere's scale
      !> (1 nm); load answers relative to the load.
      subroutine agreement(error)
         type(error_type), allocatable, intent(out) :: error
         integer :: s1, s2, k
         real(dp) :: a1, a2, tol
         do b = 1, size(BOUNDARIES)
            do p = 1, 2
               do l = 1, size(LAWS)
                  do m = 1, size(MODES)
                     do s1 = 1, size(SOLVERS) - 1
                        do s2 = s1 + 1, size(SOLVERS)
                           if (.not. (answered(s1, b, p, l, m) .and. answered(s2, b, p, l, m))) cycle
                           tol = merge(1.0e-6_dp, 1.0e-9_dp, SOLVERS(s2) == "cg")
                           do k = 1, 2
                              a1 = answers(k, s1, b, p, l, m)
                              a2 = answers(k, s2, b, p, l, m)
                              call check(error, abs(a1 - a2) <= tol*max(1.0_dp, abs(a1)), trim(SOLVERS(s1))// &
                                 " and "//trim(SOLVERS(s2))//", "//trim(BOUNDARIES(b))//", plastic "// &
                                 to_string(p - 1)//", law "//trim(LAWS(l))//", "//trim(MODES(m))//", state "// &
                                 to_string(k)//": "//to_string(a1)//" against "//to_string(a2))
                              if (allocated(error)) return
                           end do
                        end do
                     end do
                  end do
               end do
            end do
         end do
      end subroutine agreement
   end subroutine test_matrix_run

   !> The files under `prefix` other than the test's own .out and .err captures.
   function outputs_of(prefix) result(listing)
      character(len=*), intent(in) :: prefix
      character(len=:), allocatable :: listing
      call execute_command_line("ls "//prefix//".* 2>/dev/null | grep -v -e '\.out$' -e '\.err$' -e '\.listing$' > "// &
         prefix//".listing; true")
      listing = trim(read_text(prefix//".listing"))
      call execute_command_line("rm -f "//prefix//".listing")
   end function outputs_of
end module test_matrix
