!> The Appendix B program against the thesis' published numbers (Tables 4.1, 4.2,
!> section 4.4.3) and against independent calculations of the same model.
module test_legacy
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: read_deck
   use femcod_problem, only: contact_problem
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, cg_settings, &
      SOLVER_LEGACY
   use femcod_solver, only: solve_contact
   use femcod_richardson, only: convergence_rate, richardson_extrapolate
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use test_support, only: scratch_path, read_text, file_exists, contains_text
   use femcod_analytic, only: segedin_sphere
   use femcod_thesis, only: TABLE_4_1_DECKS, TABLE_4_1_APPROACH, TABLE_4_1_CENTRE_PRESSURE, TABLE_4_2_DECKS, &
      TABLE_4_2_APPROACH, TABLE_4_2_CENTRE_OVER_MEAN, TABLE_4_2_RATE_13, TABLE_4_2_RATE_24, &
      TABLE_4_2_EXTRAPOLATED_APPROACH, TABLE_4_2_EXTRAPOLATED_RATIO
   use oracles, only: love_table, exact_state, gaps_at_state
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   implicit none
   private
   public :: collect_legacy, run_deck_at_load

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_legacy(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("Table 4.1: circular punch, approach and centre pressure", test_table_4_1), &
         new_unittest("Table 4.2: square punch, approach and centre/mean pressure; Richardson", test_table_4_2), &
         new_unittest("sphere, 0.5 nm mesh: Hertz at 1000 nN, Segedin at 18000 nN", test_sphere), &
         new_unittest("rough surface: the end state against an exact solve and every gap", test_rough), &
         new_unittest("femcod run writes the three CSV files with their headers", test_run_outputs), &
         new_unittest("batch: a bad deck is reported, the others still run", test_batch) &
         ]
   end subroutine collect_legacy

   !> Run a deck of input/ to `load` and return the approach and the centre pixel's pressure.
   subroutine run_deck_at_load(name, load, approach, centre_pressure, res, status)
      character(len=*), intent(in) :: name
      real(dp), intent(in) :: load
      real(dp), intent(out) :: approach, centre_pressure
      type(contact_result), intent(out) :: res
      type(status_type), intent(inout) :: status
      type(contact_problem) :: deck
      type(contact_options) :: options
      integer :: k, c
      call read_deck("input/"//name//".deck", deck, status)
      if (status%code /= 0) return
      options%loads = [load]
      options%solver = SOLVER_LEGACY
      call solve_contact(deck, options, res, status)
      if (status%code /= 0) return
      approach = res%states(1)%approach
      c = (deck%np + 1)/2
      centre_pressure = -1
      do k = 1, size(res%contact_i)
         if (res%contact_i(k) == c .and. res%contact_j(k) == c) centre_pressure = res%contact_force(k)/deck%pixel**2
      end do
   end subroutine run_deck_at_load

   subroutine test_table_4_1(error)
      type(error_type), allocatable, intent(out) :: error
      ! Thesis Table 4.1 (1 nN): approach (nm) and centre pressure (GPa), femcod_thesis.
      character(len=*), parameter :: decks(3) = TABLE_4_1_DECKS
      real(dp), parameter :: thesis_approach(3) = TABLE_4_1_APPROACH
      real(dp), parameter :: thesis_pressure(3) = TABLE_4_1_CENTRE_PRESSURE
      real(dp) :: a, p
      type(contact_result) :: res
      type(status_type) :: status
      integer :: k
      do k = 1, 3
         call run_deck_at_load(trim(decks(k)), 1.0_dp, a, p, res, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         ! The thesis prints 3 digits; independent calculations agree within 0.16 %, so
         ! more than 0.5 % is a bug.
         call check(error, a, thesis_approach(k), rel=.true., thr=5.0e-3_dp, message=trim(decks(k))//" approach")
         if (allocated(error)) return
         call check(error, p, thesis_pressure(k), rel=.true., thr=5.0e-3_dp, message=trim(decks(k))//" pressure")
         if (allocated(error)) return
      end do
   end subroutine test_table_4_1

   subroutine test_table_4_2(error)
      type(error_type), allocatable, intent(out) :: error
      ! Thesis Table 4.2 (1 nN): approach (nm) and centre over mean pressure, femcod_thesis.
      character(len=*), parameter :: decks(4) = TABLE_4_2_DECKS
      real(dp), parameter :: thesis_approach(4) = TABLE_4_2_APPROACH
      real(dp), parameter :: thesis_ratio(4) = TABLE_4_2_CENTRE_OVER_MEAN
      real(dp) :: a(4), p, ratio(4), p13, p24, extrapolated
      type(contact_result) :: res
      type(status_type) :: status
      integer :: k
      do k = 1, 4
         call run_deck_at_load(trim(decks(k)), 1.0_dp, a(k), p, res, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         ! Mean pressure: 1 nN over the 10 nm x 10 nm punch.
         ratio(k) = p/(1.0_dp/100)
         call check(error, a(k), thesis_approach(k), rel=.true., thr=5.0e-3_dp, message=trim(decks(k))//" approach")
         if (allocated(error)) return
         call check(error, ratio(k), thesis_ratio(k), rel=.true., thr=5.0e-3_dp, message=trim(decks(k))//" ratio")
         if (allocated(error)) return
      end do
      ! Section 4.4.2 (femcod_thesis): the Richardson rates of meshes 1-3 and 2-4, printed to
      ! three decimals, and the extrapolated approach and centre/mean pressure, printed to
      ! three digits (a relative rounding of up to 1.2e-3 and 1.0e-3).
      p13 = convergence_rate(a(1), a(2), a(3), 3.0_dp)
      p24 = convergence_rate(a(2), a(3), a(4), 3.0_dp)
      call check(error, p13, TABLE_4_2_RATE_13, thr=0.005_dp, message="rate, meshes 1-3")
      if (allocated(error)) return
      call check(error, p24, TABLE_4_2_RATE_24, thr=0.005_dp, message="rate, meshes 2-4")
      if (allocated(error)) return
      extrapolated = richardson_extrapolate(a(3), a(4), 3.0_dp, p24)
      call check(error, extrapolated, TABLE_4_2_EXTRAPOLATED_APPROACH, rel=.true., thr=2.0e-3_dp, &
         message="extrapolated approach")
      if (allocated(error)) return
      call check(error, richardson_extrapolate(ratio(3), ratio(4), 3.0_dp, p24), TABLE_4_2_EXTRAPOLATED_RATIO, &
         rel=.true., thr=2.0e-3_dp, message="extrapolated centre/mean pressure")
   end subroutine test_table_4_2

   subroutine test_sphere(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp) :: estar, r, hertz, segedin, a
      call read_deck("input/sphere_d05.deck", deck, status)
      options%loads = [1000.0_dp, 18000.0_dp]
      options%solver = SOLVER_LEGACY
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      estar = 200/(1 - 0.25_dp**2)
      r = 15
      ! Hertz, eq. 4.14: delta = (9 F**2/(16 R E*^2))**(1/3).
      hertz = (9*1000.0_dp**2/(16*r*estar**2))**(1.0_dp/3)
      call check(error, res%states(1)%approach, hertz, rel=.true., thr=0.01_dp, message="Hertz at 1000 nN")
      if (allocated(error)) return
      ! Segedin's rigid sphere, the closed form of femcod_analytic (contact radius by bisection).
      call segedin_sphere(18000.0_dp, r, estar, a, segedin)
      call check(error, res%states(2)%approach, segedin, rel=.true., thr=0.005_dp, message="Segedin at 18000 nN")
   end subroutine test_sphere

   subroutine test_rough(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(contact_options) :: options
      type(contact_result) :: res
      type(status_type) :: status
      real(dp), allocatable :: table(:, :), forces(:), gap(:, :)
      real(dp) :: approach
      integer :: k, info
      call read_deck("input/rough_selfaffine_32.deck", deck, status)
      allocate(options%loads(0))
      options%solver = SOLVER_LEGACY
      call solve_contact(deck, options, res, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call check(error, res%step_contacts(1), 1, "one contact at the first step")
      if (allocated(error)) return
      call check(error, all([(res%step_load(k) >= res%step_load(k - 1) .and. res%step_approach(k) >= &
         res%step_approach(k - 1), k = 2, res%nsteps)]), "load and approach never decrease")
      if (allocated(error)) return
      ! Independent calculation (test/oracles): the final contact set solved densely by LU
      ! at the final load, and every other pixel's gap by direct sums. The springs are 1e5
      ! times stiffer than the substrate, which costs the skyline about 5 digits.
      table = love_table(deck%np)
      allocate(forces(size(res%contact_i)))
      call exact_state(deck, table, res%contact_i, res%contact_j, res%reported_load, forces, approach, info)
      call check(error, maxval(abs(res%contact_force - forces)) <= 1.0e-8_dp*maxval(forces), &
         "accumulated forces equal the exact solve: "//to_string(maxval(abs(res%contact_force - forces))/maxval(forces)))
      if (allocated(error)) return
      call check(error, res%step_approach(res%nsteps), approach, rel=.true., thr=1.0e-8_dp, message="approach")
      if (allocated(error)) return
      gap = gaps_at_state(deck, table, res%contact_i, res%contact_j, res%contact_force, res%step_approach(res%nsteps))
      do k = 1, size(res%contact_i)
         gap(res%contact_i(k), res%contact_j(k)) = huge(1.0_dp)
      end do
      call check(error, minval(gap) >= -1.0e-9_dp*res%step_approach(res%nsteps), "no missed contact: deepest "// &
         to_string(-minval(gap))//" nm")
      if (allocated(error)) return
      call check(error, all(res%contact_force >= 0), "no tensile contact force")
   end subroutine test_rough

   subroutine test_run_outputs(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix, text
      integer :: code
      prefix = scratch_path("run-square")
      call execute_command_line("rm -f "//prefix//".*")
      call run_femcod([string_type("run"), string_type("input/square_punch_n3.deck"), string_type("-o"), &
         string_type(prefix), string_type("--loads"), string_type("1,2"), string_type("--quiet")], code)
      call check(error, code, 0)
      if (allocated(error)) return
      text = read_text(prefix//".history.csv")
      call check(error, text(1:index(text, new_line("a")) - 1), &
         "step,contacts,load_nN,approach_nm,area_nm2,area_fraction,n_above_hardness,n_plastic")
      if (allocated(error)) return
      text = read_text(prefix//".loads.csv")
      call check(error, text(1:index(text, new_line("a")) - 1), &
         "load_nN,approach_nm,contacts,area_nm2,area_fraction,max_pressure_GPa,n_above_hardness,n_plastic,"// &
         "plastic_volume_nm3,kappa,patches_4,patches_8")
      if (allocated(error)) return
      ! Two requested loads: a header and two rows.
      call check(error, count([(text(code:code) == new_line("a"), code = 1, len(text))]), 3, "rows of loads.csv")
      if (allocated(error)) return
      text = read_text(prefix//".contacts.csv")
      call check(error, text(1:index(text, new_line("a")) - 1), "i,j,step,force_nN,pressure_GPa")
      if (allocated(error)) return
      ! Nine punch pixels in contact.
      call check(error, count([(text(code:code) == new_line("a"), code = 1, len(text))]), 10, "rows of contacts.csv")
      if (allocated(error)) return
      call check(error, .not. file_exists(prefix//".history.csv.part"), "no temporary file left")
   end subroutine test_run_outputs

   !> Several decks in one run: each gets its outputs (named after it, in the current
   !> directory, here the scratch directory), a bad one does not stop the others, the
   !> exit code is non-zero; the same deck twice is a usage error.
   subroutine test_batch(error)
      use, intrinsic :: iso_c_binding, only: c_char, c_int, c_null_char, c_size_t, c_ptr
      type(error_type), allocatable, intent(out) :: error
      interface
         function c_chdir(path) bind(c, name="chdir") result(rc)
            import :: c_char, c_int
            character(kind=c_char), intent(in) :: path(*)
            integer(c_int) :: rc
         end function c_chdir
         function c_getcwd(buf, size) bind(c, name="getcwd") result(p)
            import :: c_char, c_size_t, c_ptr
            character(kind=c_char), intent(out) :: buf(*)
            integer(c_size_t), value :: size
            type(c_ptr) :: p
         end function c_getcwd
      end interface
      character(kind=c_char, len=4096) :: home
      type(c_ptr) :: p
      character(len=:), allocatable :: dir
      integer :: code, ios
      home = repeat(c_null_char, len(home))
      p = c_getcwd(home, int(len(home), c_size_t))
      home = home(1:index(home, c_null_char) - 1)
      dir = scratch_path("batch")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir//" && cp input/square_punch_n3.deck "// &
         "input/circle_punch_d1.deck "//dir//"/ && printf 'bad\n' > "//dir//"/bad.deck", exitstat=ios)
      call check(error, c_chdir(dir//c_null_char) == 0, "cd into the scratch directory")
      if (allocated(error)) return
      call run_femcod([string_type("run"), string_type("square_punch_n3.deck"), string_type("bad.deck"), &
         string_type("circle_punch_d1.deck"), string_type("--loads"), string_type("1"), string_type("--quiet")], code)
      ios = c_chdir(trim(home)//c_null_char)
      call check(error, code, 3, "the bad deck's exit code")
      if (allocated(error)) return
      call check(error, file_exists(dir//"/square_punch_n3.loads.csv") .and. &
         file_exists(dir//"/circle_punch_d1.loads.csv") .and. .not. file_exists(dir//"/bad.history.csv"), &
         "both good decks ran, the bad one wrote nothing")
      if (allocated(error)) return
      call run_femcod([string_type("run"), string_type("input/square_punch_n3.deck"), &
         string_type("input/square_punch_n3.deck"), string_type("--quiet")], code)
      call check(error, code, 2, "the same deck twice is a usage error")
   end subroutine test_batch
end module test_legacy
