!> The thesis' studies (section 4.5 and chapter 3): each expected value comes from an
!> analysis, a thesis number, or an independent calculation named beside it.
module test_studies
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_deck, only: read_deck, write_deck
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type
   use femcod_cli, only: run_femcod
   use femcod_love, only: surface_compliance, love_influence
   use femcod_resolution, only: uncoupled_curve, mccool_parameters, mccool_surface, mccool_area, gw_integral, &
      richardson_area, interpolate_area
   use femcod_resolution_study, only: level_deck
   use femcod_surfaces, only: sinusoid_surface, weierstrass_mandelbrot, self_affine_surface
   use femcod_summits, only: summit_statistics, summit_search, summit_power_laws, profile_psd, psd_dimension, &
      structure_function, structure_dimension, paraboloid_fit
   use femcod_multiscale, only: roughness_template, multiscale_result, multiscale_hertz, hertz_area
   use femcod_contact_result, only: contact_result
   use femcod_solver_options, only: contact_options, cg_settings, &
      SOLVER_INCREMENTAL, SOLVER_LEGACY
   use femcod_solver, only: solve_contact
   use femcod_richardson, only: power_law_fit
   use femcod_thesis, only: PIXEL_COMPLIANCE
   use testdrive, only: new_unittest, unittest_type, error_type, check, to_string
   use oracles, only: love_table, event_path
   use test_support, only: scratch_path, read_text, file_exists, remove_scratch, contains_text
   implicit none
   private
   public :: collect_studies

   real(dp), parameter :: pi = acos(-1.0_dp)

contains

   subroutine collect_studies(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("single-pixel compliance 5.39e-4 nm/nN of section 4.5", test_pixel_compliance), &
         new_unittest("uncoupled voxels equal direct sums", test_uncoupled), &
         new_unittest("Greenwood-Williamson integrals against closed forms", test_gw_integrals), &
         new_unittest("McCool moments of a two-way cosine, exact differences", test_mccool_moments), &
         new_unittest("McCool area inverts the pressure", test_mccool_inversion), &
         new_unittest("Richardson of curves converging linearly is exact", test_richardson_curves), &
         new_unittest("down-sampling chain, levels and MAXCONT", test_level_deck), &
         new_unittest("pixels above the hardness per step: incremental = legacy", test_hardness_steps), &
         new_unittest("pixels above the hardness per step: the dense oracle's event path", test_hardness_oracle), &
         new_unittest("femcod resolution writes the study", test_resolution_command), &
         new_unittest("femcod resolution --shear-strength/--shear-slope: tau0 A + alpha F on every row", &
            test_resolution_friction), &
         new_unittest("Fig. 4.21 capped curve: the elastic history until the first pixel reaches H", &
            test_capped_curve), &
         new_unittest("summits of the sinusoid eq. 3.3: R = 100 nm, then R ~ d^2", test_sinusoid_summits), &
         new_unittest("paraboloid fit of an exact elliptic paraboloid", test_paraboloid), &
         new_unittest("Weierstrass-Mandelbrot radius exponent near D = 1.4 (eq. 3.8)", test_wm_radius_exponent), &
         new_unittest("self-affine H = 0.8: profile dimension 1.2 from PSD and structure function", test_fractal), &
         new_unittest("Appendix A: n asperities against one (eq. A.1)", test_appendix_a), &
         new_unittest("multiscale: area independent of s when one asperity per host", test_scale_independence), &
         new_unittest("multiscale: close-packed spots fit on their hosts", test_close_packed), &
         new_unittest("femcod summits and multiscale write their files", test_surface_commands), &
         new_unittest("multiscale takes E* from the deck's materials, --estar from a height file's user", &
            test_multiscale_estar), &
         new_unittest("summits: a fit range with fewer than two points determines no dimension", test_empty_fit) &
         ]
   end subroutine collect_studies

   !> Section 4.5: a pixel of the 5 um, 512 x 512 image (d = 9.765625 nm), E = 200 GPa,
   !> nu = 0.25, deflects at its centre by 5.39e-4 nm per nN (the thesis prints the value
   !> with the unit N/m; as m/N = nm/nN it is the compliance (1-nu^2)/(pi E d) 4 ln(1+sqrt 2)).
   subroutine test_pixel_compliance(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: c
      c = surface_compliance(200.0_dp, 0.25_dp, 5000.0_dp/512)*love_influence(0, 0)
      call check(error, abs(c - PIXEL_COMPLIANCE) < 0.005e-4_dp, "compliance "//to_string(c))
   end subroutine test_pixel_compliance

   !> The sorted-prefix evaluation against the definition, pixel by pixel.
   subroutine test_uncoupled(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: gaps(200), d(7), load(7), area(7), expect
      integer :: k, i
      do i = 1, size(gaps)
         gaps(i) = modulo(i*0.7548776662_dp, 1.0_dp)*3
      end do
      gaps(17) = 0
      d = [0.0_dp, 0.01_dp, 0.5_dp, 1.0_dp, gaps(5), 2.9_dp, 10.0_dp]
      call uncoupled_curve(gaps, 0.25_dp, 2.0_dp, d, load, area)
      do k = 1, size(d)
         expect = 0
         do i = 1, size(gaps)
            if (gaps(i) < d(k)) expect = expect + (d(k) - gaps(i))/0.25_dp
         end do
         call check(error, abs(load(k) - expect) <= 1.0e-12_dp*max(expect, 1.0_dp), "load at "//to_string(d(k)))
         if (allocated(error)) return
         call check(error, area(k), count(gaps < d(k))*4.0_dp)
         if (allocated(error)) return
      end do
   end subroutine test_uncoupled

   !> F_1(h) = phi(h) - h Q(h) (Q the normal upper tail); F_3/2(0) = 2^(3/4) Gamma(5/4)
   !> / (2 sqrt pi) (half the 3/2 absolute moment of the normal distribution).
   subroutine test_gw_integrals(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: h, f1
      integer :: k
      do k = -2, 6
         h = 0.5_dp*k
         f1 = exp(-h*h/2)/sqrt(2*pi) - h*0.5_dp*erfc(h/sqrt(2.0_dp))
         call check(error, abs(gw_integral(1.0_dp, h) - f1) < 1.0e-11_dp*max(f1, 1.0e-3_dp), "F1 at "//to_string(h))
         if (allocated(error)) return
      end do
      call check(error, abs(gw_integral(1.5_dp, 0.0_dp) - 2**0.75_dp*gamma(1.25_dp)/(2*sqrt(pi))) < 1.0e-11_dp, &
         "F3/2(0)")
   end subroutine test_gw_integrals

   !> z = A cos(k y) + A cos(k x), 8 pixels per period: over whole periods the forward
   !> differences give m2 = A^2 (1 - cos kd)/d^2 and the second differences
   !> m4 = A^2 (2 - 2 cos kd)^2 / (2 d^4); m0 = A^2.
   subroutine test_mccool_moments(error)
      type(error_type), allocatable, intent(out) :: error
      type(mccool_parameters) :: p
      real(dp), parameter :: a = 1.5_dp, d = 2.0_dp, kd = 2*pi/8
      p = mccool_surface(wave(64), d)
      call check(error, abs(p%m0 - a*a) < 1.0e-13_dp, "m0")
      if (allocated(error)) return
      p = mccool_surface(wave(65), d)
      call check(error, abs(p%m2 - a*a*(1 - cos(kd))/d**2) < 1.0e-13_dp, "m2 "//to_string(p%m2))
      if (allocated(error)) return
      p = mccool_surface(wave(66), d)
      call check(error, abs(p%m4 - a*a*(2 - 2*cos(kd))**2/(2*d**4)) < 1.0e-13_dp, "m4 "//to_string(p%m4))
   contains
      function wave(n) result(z)
         integer, intent(in) :: n
         real(dp) :: z(n, n)
         integer :: i, j
         do j = 1, n
            do i = 1, n
               z(i, j) = a*cos(kd*i) + a*cos(kd*j)
            end do
         end do
      end function wave
   end subroutine test_mccool_moments

   !> At separations h0 the pressure and area follow from the integrals directly; the
   !> tabulated inversion must return that area (interpolation error only).
   subroutine test_mccool_inversion(error)
      type(error_type), allocatable, intent(out) :: error
      type(mccool_parameters) :: p
      real(dp) :: pressure(3), area(3), expect(3), h0(3)
      integer :: k
      p%density = 4.6e-5_dp
      p%radius = 280
      p%sigma = 2.55_dp
      h0 = [3.0_dp, 1.234_dp, -0.5_dp]
      do k = 1, 3
         pressure(k) = 4.0_dp/3*p%density*200*sqrt(p%radius)*p%sigma**1.5_dp*gw_integral(1.5_dp, h0(k))
         expect(k) = pi*p%density*p%radius*p%sigma*gw_integral(1.0_dp, h0(k))*1.0e8_dp
      end do
      call mccool_area(p, 200.0_dp, 1.0e8_dp, pressure, area)
      do k = 1, 3
         call check(error, abs(area(k) - expect(k)) < 1.0e-4_dp*expect(k), "h0 = "//to_string(h0(k))//": "// &
            to_string(area(k))//" against "//to_string(expect(k)))
         if (allocated(error)) return
      end do
   end subroutine test_mccool_inversion

   !> Areas A_h(L) = A0(L) + C h on piecewise linear curves: the rate-1 extrapolation
   !> from h = 2 (coarse) and h = 1 (fine) returns A0 exactly at every fine load.
   subroutine test_richardson_curves(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: lc(5), ac(5), lf(9), af(9), out(9)
      logical :: keep(9)
      integer :: k
      lc = [0.0_dp, 1.0_dp, 2.0_dp, 3.0_dp, 4.0_dp]
      ac = a0(lc) + 2*0.3_dp
      lf = [(0.5_dp*k, k = 0, 8)]
      af = a0(lf) + 0.3_dp
      call richardson_area(lc, ac, lf, af, 2.0_dp, 1.0_dp, out, keep)
      call check(error, all(keep), "all fine loads inside the coarse history")
      if (allocated(error)) return
      call check(error, maxval(abs(out - a0(lf))) < 1.0e-14_dp, "extrapolated to the limit")
      if (allocated(error)) return
      call check(error, interpolate_area(lc, ac, 5.0_dp) < 0, "outside the history")
   contains
      elemental real(dp) function a0(l)
         real(dp), intent(in) :: l
         ! Linear between the coarse loads, so that interpolation is exact.
         a0 = 1 + 2*l
      end function a0
   end subroutine test_richardson_curves

   !> Halving a 12 x 12 deck: subsample keeps rows/columns 1, 3, 5, ...; average keeps
   !> the mean height; pixel doubles; MAXCONT scales with the pixel count; a level not
   !> on the chain is a usage error.
   subroutine test_level_deck(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck, level
      type(status_type) :: status
      integer :: i, j
      deck%label = "t"
      deck%np = 12
      deck%pixel = 2
      deck%maxcont = 40
      deck%young = [200.0_dp, 2.0e7_dp, 2.0e7_dp]
      deck%poisson = 0.25_dp
      allocate(deck%lower(12, 12), deck%upper(12, 12))
      do j = 1, 12
         do i = 1, 12
            deck%lower(i, j) = modulo(i*7 + j*13, 10)*0.1_dp
         end do
      end do
      deck%upper = 0
      call level_deck(deck, 3, "subsample", level, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call check(error, level%pixel, 8.0_dp)
      if (allocated(error)) return
      call check(error, all(level%lower == deck%lower(1::4, 1::4)), "odd/odd twice")
      if (allocated(error)) return
      call check(error, level%maxcont, nint(40*(3.0_dp/12)**2))
      if (allocated(error)) return
      call level_deck(deck, 6, "average", level, status)
      call check(error, abs(sum(level%lower)/36 - sum(deck%lower)/144) < 1.0e-14_dp, "mean kept")
      if (allocated(error)) return
      call level_deck(deck, 5, "average", level, status)
      call check(error, status%code, 2)
      if (allocated(error)) return
      call check(error, contains_text(status%message, "cannot be reached"), status%message)
   end subroutine test_level_deck

   !> The two solvers count the contacts above the hardness at the end of every step
   !> independently (their own forces); on the 1 nm sphere deck the counts must agree.
   subroutine test_hardness_steps(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      type(contact_options) :: options
      type(contact_result) :: a, b
      integer :: n
      call read_deck("input/sphere_d1.deck", deck, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      options%hardness = 5
      options%max_contacts = 400
      allocate(options%loads(0))
      options%solver = SOLVER_INCREMENTAL
      call solve_contact(deck, options, a, status)
      options%solver = SOLVER_LEGACY
      call solve_contact(deck, options, b, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      n = min(a%nsteps, b%nsteps)
      call check(error, n > 3, "steps: "//to_string(n))
      if (allocated(error)) return
      call check(error, all(a%step_above_hardness(1:n) == b%step_above_hardness(1:n)), "per-step counts")
      if (allocated(error)) return
      call check(error, maxval(a%step_above_hardness(1:n)) > 0, "some contacts above 5 GPa")
      if (allocated(error)) return
      call check(error, a%step_above_hardness(a%nsteps), count(a%contact_force/deck%pixel**2 > 5))
   end subroutine test_hardness_steps

   !> The same counts against an outside reference (test/oracles' brute-force event path:
   !> dense LU solves with the quadruple-precision Love table): at the load where each
   !> step ends, the contacts whose pressure is above H = 5 GPa, on the 1 nm sphere to
   !> its MAXCONT. The solver's steps are compressed to distinct loads (tied pixels join
   !> in one event of the oracle).
   subroutine test_hardness_oracle(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: status
      type(contact_options) :: options
      type(contact_result) :: a
      real(dp), allocatable :: table(:, :), loads(:)
      integer, allocatable :: counts(:), above(:)
      integer :: m, k, n
      logical :: released
      call read_deck("input/sphere_d1.deck", deck, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      options%hardness = 5
      allocate(options%loads(0))
      options%solver = SOLVER_INCREMENTAL
      call solve_contact(deck, options, a, status)
      call check(error, status%code, 0, status%message)
      if (allocated(error)) return
      table = love_table(deck%np)
      allocate(loads(deck%maxcont + 1), counts(deck%maxcont + 1), above(deck%maxcont + 1))
      call event_path(deck, table, 1.0e-9_dp, deck%maxcont + 1, huge(1.0_dp), loads, counts, m, released, &
         hardness=5.0_dp, above=above)
      call check(error, m > 10 .and. .not. released, "the oracle's path: "//to_string(m)//" events")
      if (allocated(error)) return
      n = 0
      do k = 1, a%nsteps
         if (k > 1) then
            if (abs(a%step_load(k) - a%step_load(k - 1)) <= 1.0e-12_dp*a%step_load(k)) cycle
         end if
         n = n + 1
         if (n > m) exit
         ! Loads within 1e-8: measured 1.05e-9 at worst (the last event, 43, with over 300 contacts, the
         ! two dense solves of 300 x 300 systems with the deck's 1e5 rigid factor), a decade.
         call check(error, abs(a%step_load(k) - loads(n)) <= 1.0e-8_dp*loads(n), "event "//to_string(n)// &
            ": load "//to_string(a%step_load(k))//" vs the oracle's "//to_string(loads(n)))
         if (allocated(error)) return
         call check(error, a%step_above_hardness(k), above(n), "event "//to_string(n)//" at "// &
            to_string(loads(n))//" nN: pixels above 5 GPa")
         if (allocated(error)) return
      end do
      call check(error, n == m .and. maxval(above(1:m)) > 0, "events compared: "//to_string(n)//" of "// &
         to_string(m)//"; some above 5 GPa")
   end subroutine test_hardness_oracle

   !> The capped curve of Fig. 4.21 (PREFIX.hardness_capped.csv: the finest level solved
   !> again with the pressures capped at H = 5 GPa, the event path's plastic events). A row
   !> is the state where the next event happens, with the plastic pixels before it (as the
   !> contacts are counted before the next one joins). So until the first pixel reaches H
   !> the capped path is the elastic one: the loads of PREFIX.resolution.csv row for row,
   !> to the digit; the row where the first pixel reaches H comes at a load no larger than
   !> the elastic row's (the cap came first); from the next row on pixels are plastic, never
   !> more than there are contacts.
   subroutine test_capped_curve(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix, capped, elastic
      character(len=64), allocatable :: crow(:, :), erow(:, :)
      real(dp) :: cload, eload
      integer :: code, k, first, plastic, contacts
      prefix = scratch_path("capped-curve")
      call run_femcod([string_type("resolution"), string_type("input/rough_selfaffine_32.deck"), &
         string_type("--levels"), string_type("32"), string_type("--hardness"), string_type("5"), &
         string_type("-o"), string_type(prefix), string_type("--quiet"), string_type("--force")], code)
      call check(error, code, 0)
      if (allocated(error)) return
      capped = read_text(prefix//".hardness_capped.csv")
      elastic = read_text(prefix//".resolution.csv")
      call check(error, capped(1:index(capped, new_line("a")) - 1), &
         "np,step,load_nN,area_fraction,contacts,n_plastic,fraction_plastic")
      if (allocated(error)) return
      crow = csv_rows(capped, 7)
      erow = csv_rows(elastic, 5)
      first = 0
      do k = 1, size(crow, 2)
         read(crow(6, k), *) plastic
         read(crow(5, k), *) contacts
         call check(error, plastic >= 0 .and. plastic <= contacts, "row "//to_string(k))
         if (allocated(error)) return
         if (plastic > 0 .and. first == 0) first = k
      end do
      call check(error, first > 2, "plastic rows in the capped curve (first "//to_string(first)//")")
      if (allocated(error)) return
      do k = 1, first - 2
         call check(error, trim(crow(3, k)), trim(erow(3, k)), "row "//to_string(k)//": the load before H")
         if (allocated(error)) return
      end do
      read(crow(3, first - 1), *) cload
      read(erow(3, first - 1), *) eload
      call check(error, cload <= eload, "the first pixel reaches H at "//to_string(cload)//" nN, after the elastic "// &
         "event at "//to_string(eload)//" nN")
   contains
      !> The rows after the header of a CSV text, `nf` fields each (64 characters).
      function csv_rows(text, nf) result(rows)
         character(len=*), intent(in) :: text
         integer, intent(in) :: nf
         character(len=64), allocatable :: rows(:, :)
         character(len=:), allocatable :: rest, line
         integer :: m, at, start, f
         rest = text(index(text, new_line("a")) + 1:)
         allocate(rows(nf, count([(rest(m:m) == new_line("a"), m = 1, len(rest))])))
         rows = ""
         do m = 1, size(rows, 2)
            line = rest(1:index(rest, new_line("a")) - 1)
            rest = rest(index(rest, new_line("a")) + 1:)
            start = 1
            f = 0
            do at = 1, len(line) + 1
               if (at > len(line) .or. line(min(at, len(line)):min(at, len(line))) == ",") then
                  f = f + 1
                  if (f <= nf) rows(f, m) = line(start:at - 1)
                  start = at + 1
               end if
            end do
         end do
      end function csv_rows
   end subroutine test_capped_curve

   !> The command on a 32 x 32 deck, levels 32 and 16: every file, the headers of its
   !> help (femcod resolution --help), and the fitted exponent equal to an independent fit
   !> of the coupled rows.
   subroutine test_resolution_command(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix, text
      character(len=*), parameter :: suffixes(11) = [character(len=22) :: ".resolution.csv", ".powerlaw.csv", &
         ".estimates.csv", ".hardness.csv", ".load_displacement.svg", ".area_displacement.svg", ".area_pressure.svg", &
         ".richardson.svg", ".hardness.svg", ".hardness_capped.csv", ".resolution.json"]
      integer :: code, k
      prefix = scratch_path("resolution")
      do k = 1, size(suffixes)
         call remove_scratch(prefix//trim(suffixes(k)))
      end do
      call run_femcod([string_type("resolution"), string_type("input/rough_selfaffine_32.deck"), &
         string_type("--levels"), string_type("32,16"), string_type("--method"), string_type("average"), &
         string_type("-o"), string_type(prefix), string_type("--quiet")], code)
      call check(error, code, 0)
      if (allocated(error)) return
      do k = 1, size(suffixes)
         call check(error, file_exists(prefix//trim(suffixes(k))), prefix//trim(suffixes(k)))
         if (allocated(error)) return
      end do
      text = read_text(prefix//".resolution.csv")
      call check(error, text(1:index(text, new_line("a")) - 1), "np,method,load_nN,approach_nm,area_nm2")
      if (allocated(error)) return
      call check(error, contains_text(read_text(prefix//".powerlaw.csv"), "np,exponent,prefactor"), "powerlaw header")
      if (allocated(error)) return
      text = read_text(prefix//".estimates.csv")
      call check(error, text(1:index(text, new_line("a")) - 1), "np,model,load_nN,area_nm2")
      if (allocated(error)) return
      call check(error, contains_text(text, "16,uncoupled,") .and. contains_text(text, "32,mccool,") .and. &
         contains_text(text, "32,richardson,") .and. contains_text(text, "16,coupled,"), "all four models")
      if (allocated(error)) return
      call check_fit(prefix, error)
      if (allocated(error)) return
      ! Existing results: refused with exit 5.
      call run_femcod([string_type("resolution"), string_type("input/rough_selfaffine_32.deck"), &
         string_type("--levels"), string_type("32"), string_type("-o"), string_type(prefix), string_type("--quiet")], code)
      call check(error, code, 5)
   end subroutine test_resolution_command

   !> The resolution study with the shear model (tau0 = 0.05 GPa, alpha = 0.1), elastic:
   !> on every row of every level, friction_nN = tau0 area + alpha load (each contact
   !> pixel carries tau0 + alpha p, and the forces sum to the load) and the coefficient
   !> is friction over load, from the row's own area and load (this test's parser).
   subroutine test_resolution_friction(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix, text, line
      character(len=16) :: np, method
      real(dp) :: load, approach, area, ft, mu
      integer :: code, k, p, q, ios, rows
      character(len=*), parameter :: suffixes(11) = [character(len=22) :: ".resolution.csv", ".powerlaw.csv", &
         ".estimates.csv", ".hardness.csv", ".load_displacement.svg", ".area_displacement.svg", ".area_pressure.svg", &
         ".richardson.svg", ".hardness.svg", ".hardness_capped.csv", ".resolution.json"]
      prefix = scratch_path("resolution_friction")
      do k = 1, size(suffixes)
         call remove_scratch(prefix//trim(suffixes(k)))
      end do
      call run_femcod([string_type("resolution"), string_type("input/rough_selfaffine_32.deck"), &
         string_type("--levels"), string_type("32,16"), string_type("--shear-strength"), string_type("0.05"), &
         string_type("--shear-slope"), string_type("0.1"), string_type("-o"), string_type(prefix), &
         string_type("--quiet")], code)
      call check(error, code, 0)
      if (allocated(error)) return
      text = read_text(prefix//".resolution.csv")
      call check(error, text(1:index(text, new_line("a")) - 1), &
         "np,method,load_nN,approach_nm,area_nm2,friction_nN,friction_coefficient")
      if (allocated(error)) return
      rows = 0
      p = index(text, new_line("a")) + 1
      do while (p < len(text))
         q = p + index(text(p:), new_line("a")) - 2
         line = commas_to_blanks(text(p:q))
         p = q + 2
         read(line, *, iostat=ios) np, method, load, approach, area, ft, mu
         call check(error, ios, 0, "row "//line)
         if (allocated(error)) return
         call check(error, ft, 0.05_dp*area + 0.1_dp*load, rel=.true., thr=1.0e-12_dp, message="row "//line)
         if (allocated(error)) return
         call check(error, mu, ft/load, rel=.true., thr=1.0e-15_dp, message="row "//line)
         if (allocated(error)) return
         rows = rows + 1
      end do
      call check(error, rows > 20, "rows")
   end subroutine test_resolution_friction

   !> Refit area = c load^e over the NP = 32 rows of resolution.csv (this test's own
   !> parser and least squares) and compare with powerlaw.csv.
   subroutine check_fit(prefix, error)
      character(len=*), intent(in) :: prefix
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: text, line
      real(dp) :: x(4000), y(4000), e, c, ap, load, area, e_file
      character(len=16) :: np, method
      integer :: n, p, q, ios
      text = read_text(prefix//".resolution.csv")
      n = 0
      p = index(text, new_line("a")) + 1
      do while (p < len(text))
         q = p + index(text(p:), new_line("a")) - 2
         line = text(p:q)
         p = q + 2
         line = commas_to_blanks(line)
         read(line, *, iostat=ios) np, method, load, ap, area
         if (ios /= 0) exit
         if (trim(np) /= "32" .or. load <= 0 .or. area <= 0) cycle
         n = n + 1
         x(n) = log(load)
         y(n) = log(area)
      end do
      e = (n*sum(x(1:n)*y(1:n)) - sum(x(1:n))*sum(y(1:n)))/(n*sum(x(1:n)**2) - sum(x(1:n))**2)
      c = exp((sum(y(1:n)) - e*sum(x(1:n)))/n)
      text = read_text(prefix//".powerlaw.csv")
      p = index(text, "32,")
      line = commas_to_blanks(text(p:p + index(text(p:), new_line("a")) - 2))
      read(line, *) np, e_file
      call check(error, abs(e - e_file) < 1.0e-10_dp, "exponent "//to_string(e_file)//" refit "//to_string(e))
      if (allocated(error)) return
      call check(error, n > 20, "rows")
   end subroutine check_fit

   pure function commas_to_blanks(s) result(t)
      character(len=*), intent(in) :: s
      character(len=len(s)) :: t
      integer :: k
      t = s
      do k = 1, len(t)
         if (t(k:k) == ",") t(k:k) = " "
      end do
   end function commas_to_blanks

   !> Eq. 3.3, z = cos(x/10) cos(y/10) nm on a 1 nm grid: near a peak z ~ 1 - (x^2+y^2)/200,
   !> so R = w^2/A = 100 nm at small boxes (thesis Fig. 3.3). For boxes beyond the
   !> period (d >= 20 pi) the fit through the fixed maximum makes R ~ b^2 (eqs. 3.4-3.5).
   subroutine test_sinusoid_summits(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: z(:, :)
      type(summit_statistics), allocatable :: st(:)
      type(status_type) :: status
      real(dp) :: slope
      integer :: k
      allocate(z(401, 401))
      call sinusoid_surface(401, 1.0_dp, 1.0_dp, 10.0_dp, z)
      call summit_search(z, 1.0_dp, [1, 2, 3, 64, 96], st, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      do k = 1, 3
         call check(error, abs(st(k)%mean_radius - 100) < 2.5_dp, "n = "//to_string(k)//": R = "// &
            to_string(st(k)%mean_radius))
         if (allocated(error)) return
      end do
      slope = log(st(5)%mean_radius/st(4)%mean_radius)/log(st(5)%box/st(4)%box)
      call check(error, abs(slope - 2) < 0.1_dp, "large-box slope "//to_string(slope))
   end subroutine test_sinusoid_summits

   !> z = z0 - x^2/(2 Rx) - y^2/(2 Ry) sampled exactly: the fit returns Rx and Ry.
   subroutine test_paraboloid(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp) :: z(21, 21), rx, ry
      integer :: i, j
      do j = 1, 21
         do i = 1, 21
            z(i, j) = 5 - ((j - 11)*0.5_dp)**2/(2*30) - ((i - 11)*0.5_dp)**2/(2*70)
         end do
      end do
      call paraboloid_fit(z, 11, 11, 6, 0.5_dp, rx, ry)
      call check(error, abs(rx - 30) < 1.0e-10_dp .and. abs(ry - 70) < 1.0e-10_dp, "Rx "//to_string(rx)//", Ry "// &
         to_string(ry))
   end subroutine test_paraboloid

   !> W-M surface of eq. 3.6 with the thesis' parameters (Ds = 2.4, G = 1.36e-2 nm, gamma
   !> = 1.5, 1 nm to 1 um, M = 10) on 512 x 512 pixels of 1000/512 nm: the mean summit
   !> radius grows as d^D with D = Ds - 1 = 1.4 (Majumdar-Bhushan, eq. 3.8; the thesis'
   !> Fig. 3.5c fits 1.39 and 1.41). Over boxes of 33-252 nm three seeds give 1.26-1.34
   !> (the slope still rises towards 1.4 at the largest boxes), hence the band.
   subroutine test_wm_radius_exponent(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: z(:, :)
      type(summit_statistics), allocatable :: st(:)
      type(status_type) :: status
      real(dp) :: e(3), p(3)
      allocate(z(512, 512))
      call weierstrass_mandelbrot(512, 1000.0_dp/512, 2.4_dp, 1.36e-2_dp, 1.5_dp, 1000.0_dp, 1.0_dp, 10, 1, z)
      call summit_search(z, 1000.0_dp/512, [8, 11, 16, 23, 32, 45, 64], st, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call summit_power_laws(st, e, p)
      call check(error, e(3) > 1.25_dp .and. e(3) < 1.55_dp, "radius exponent "//to_string(e(3)))
      if (allocated(error)) return
      ! Density falls and heights grow with the box (Fig. 3.5a, b).
      call check(error, e(1) < -1.5_dp .and. e(2) > 0.3_dp, "density "//to_string(e(1))//", height "//to_string(e(2)))
   end subroutine test_wm_radius_exponent

   !> A self-affine surface with 2-D spectrum ~ q^-2(1+H) has profile spectra ~
   !> q^-(1+2H) and structure function ~ tau^2H for tau << L: with eq. 3.1 and eq. 2.15
   !> both give the profile dimension D = 2 - H = 1.2 for H = 0.8.
   subroutine test_fractal(error)
      type(error_type), allocatable, intent(out) :: error
      real(dp), allocatable :: z(:, :), f(:), pw(:), tau(:), s(:)
      real(dp) :: dpsd, slope, dsf, g
      allocate(z(512, 512))
      call self_affine_surface(512, 1.0_dp, 0.8_dp, 1.0_dp, 3, z)
      call profile_psd(z, 1.0_dp, f, pw)
      call psd_dimension(f, pw, 4/512.0_dp, 0.25_dp, dpsd, slope)
      call check(error, abs(dpsd - 1.2_dp) < 0.05_dp, "PSD dimension "//to_string(dpsd))
      if (allocated(error)) return
      call structure_function(z, 1.0_dp, 128, tau, s)
      call structure_dimension(tau, s, 1.0_dp, 32.0_dp, dsf, g)
      call check(error, abs(dsf - 1.2_dp) < 0.1_dp, "structure-function dimension "//to_string(dsf))
   end subroutine test_fractal

   !> Eq. A.1 against eq. 3.13: n equal asperities of radius r at one height against one
   !> of radius R under the same load: A_n / A = n^(1/3) (r/R)^(2/3) (Fig. A.2: n = 100).
   subroutine test_appendix_a(error)
      type(error_type), allocatable, intent(out) :: error
      type(roughness_template) :: many, one
      type(multiscale_result) :: rn, r1
      type(status_type) :: status
      real(dp), parameter :: ratios(3) = [1.0_dp, 10.0_dp, 40.0_dp]
      real(dp) :: ratio
      integer :: k
      do k = 1, 3
         ratio = ratios(k)
         allocate(many%heights(100), many%radii(100))
         many%heights = 3
         many%radii = 1000/ratio
         many%box = 100
         many%density = 1.0e-4_dp
         one%heights = [3.0_dp]
         one%radii = [1000.0_dp]
         one%box = 100
         one%density = 1.0e-4_dp
         call multiscale_hertz(many, 0.6_dp, 1.25_dp, -1.87_dp, 5.0_dp, 1, 1.0e4_dp, 200.0_dp, "density", rn, status)
         call multiscale_hertz(one, 0.6_dp, 1.25_dp, -1.87_dp, 5.0_dp, 1, 1.0e4_dp, 200.0_dp, "density", r1, status)
         call check(error, status%code, 0)
         if (allocated(error)) return
         call check(error, abs(rn%area(1)/r1%area(1) - 100**(1.0_dp/3)*(1/ratio)**(2.0_dp/3)) < 1.0e-10_dp, &
            "R/r = "//to_string(ratio)//": "//to_string(rn%area(1)/r1%area(1)))
         if (allocated(error)) return
         call check(error, abs(r1%area(1) - hertz_area(1000.0_dp, 1.0e4_dp, 200.0_dp)) < 1.0e-10_dp*r1%area(1), &
            "single asperity is Hertz")
         if (allocated(error)) return
         deallocate(many%heights, many%radii)
      end do
   end subroutine test_appendix_a

   !> With the asperity-density constraint and a density too low for a second asperity,
   !> each host carries the tallest finer asperity alone, so the area at the smallest
   !> scale d_K is sum_i pi (3 F_i R_top (d_K/d_1)^eR / (4 E*))^(2/3) over the first
   !> scale's loads F_i (from this test's own load sharing): it depends on d_K, not on
   !> how s reaches it (section 3.3.1).
   !> s = 2 with 4 scales and s = 8 with 2 scales both end at d_1/8.
   subroutine test_scale_independence(error)
      type(error_type), allocatable, intent(out) :: error
      type(roughness_template) :: t
      type(multiscale_result) :: a, b
      type(status_type) :: status
      real(dp) :: f(5), ar(5), expect
      t%heights = [10.0_dp, 9.0_dp, 8.5_dp, 7.0_dp, 2.0_dp]
      t%radii = [300.0_dp, 500.0_dp, 200.0_dp, 800.0_dp, 100.0_dp]
      t%box = 400
      t%density = 1.0e-12_dp
      call multiscale_hertz(t, 0.6_dp, 1.25_dp, -1.87_dp, 2.0_dp, 4, 5.0e4_dp, 200.0_dp, "density", a, status)
      call multiscale_hertz(t, 0.6_dp, 1.25_dp, -1.87_dp, 8.0_dp, 2, 5.0e4_dp, 200.0_dp, "density", b, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call hertz_sharing(t%heights, t%radii, 5.0e4_dp, 200.0_dp, f, ar)
      expect = sum(hertz_area(300*(1/8.0_dp)**1.25_dp, pack(f, f > 0), 200.0_dp))
      call check(error, abs(a%area(4) - expect) < 1.0e-10_dp*expect, "s = 2: "//to_string(a%area(4))//" against "// &
         to_string(expect))
      if (allocated(error)) return
      call check(error, abs(b%area(2) - expect) < 1.0e-10_dp*expect, "s = 8: "//to_string(b%area(2)))
      if (allocated(error)) return
      call check(error, abs(a%length(4) - 50) < 1.0e-12_dp .and. abs(b%length(2) - 50) < 1.0e-12_dp, "d_K = d_1/8")
   end subroutine test_scale_independence

   !> This test's own load sharing among Hertz asperities under a rigid flat (not the
   !> model's routine): the approach delta from sum (4/3) E* sqrt(R_i) w_i^(3/2) = load,
   !> w_i = h_i - max(h) + delta > 0, by Newton's method from the tallest asperity's
   !> Hertz approach (the sum is convex and increasing in delta, so Newton from above
   !> decreases monotonically to the root); forces and areas pi R_i w_i.
   pure subroutine hertz_sharing(h, r, load, estar, f, a)
      real(dp), intent(in) :: h(:), r(:), load, estar
      real(dp), intent(out) :: f(:), a(:)
      real(dp) :: delta, w(size(h)), g, dg
      integer :: it
      delta = (3*load/(4*estar*sqrt(r(maxloc(h, 1)))))**(2.0_dp/3)
      do it = 1, 100
         w = max(h - maxval(h) + delta, 0.0_dp)
         g = sum(4.0_dp/3*estar*sqrt(r)*w**1.5_dp) - load
         dg = sum(2*estar*sqrt(r)*sqrt(w))
         delta = delta - g/dg
      end do
      w = max(h - maxval(h) + delta, 0.0_dp)
      f = 4.0_dp/3*estar*sqrt(r)*w**1.5_dp
      a = pi*r*w
   end subroutine hertz_sharing

   !> Close-packed constraint: at the second scale the finer contacts on each host must
   !> cover at most pi/(2 sqrt 3) of its contact area (checked here by re-solving the
   !> first scale), and the area must fall with the number of scales (Fig. 3.8).
   subroutine test_close_packed(error)
      type(error_type), allocatable, intent(out) :: error
      type(roughness_template) :: t
      type(multiscale_result) :: r
      type(status_type) :: status
      real(dp) :: f(6), ar(6)
      integer :: i
      t%heights = [(10 - 0.7_dp*i, i = 1, 6)]
      t%radii = [(200 + 50.0_dp*i, i = 1, 6)]
      t%box = 400
      t%density = 1.0e-5_dp
      call multiscale_hertz(t, 1.0_dp, 1.0_dp, -2.0_dp, 5.0_dp, 3, 1.0e4_dp, 200.0_dp, "close-packed", r, status)
      call check(error, status%code, 0)
      if (allocated(error)) return
      call hertz_sharing(t%heights, t%radii, 1.0e4_dp, 200.0_dp, f, ar)
      call check(error, abs(r%area(1) - sum(ar)) < 1.0e-10_dp*sum(ar), "first scale: "//to_string(r%area(1)))
      if (allocated(error)) return
      call check(error, r%area(2) <= pi/(2*sqrt(3.0_dp))*r%area(1)*(1 + 1.0e-12_dp), "spots fit")
      if (allocated(error)) return
      call check(error, r%area(3) < r%area(2) .and. r%area(2) < r%area(1), "area falls with the scales")
      if (allocated(error)) return
      call check(error, r%contacts(2) >= r%contacts(1), "at least one finer contact per host")
   end subroutine test_close_packed

   !> Both commands on the 32 x 32 rough deck and on an ASCII matrix: files written, the
   !> summit table's header of its help (femcod summits --help); a bad size is a usage
   !> error with no files.
   subroutine test_surface_commands(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: prefix, text
      integer :: code
      prefix = scratch_path("summits")
      call remove_scratch(prefix//".summits.csv")
      call run_femcod([string_type("summits"), string_type("input/rough_selfaffine_32.deck"), string_type("--sizes"), &
         string_type("1,2,3"), string_type("-o"), string_type(prefix), string_type("--quiet"), string_type("--force")], code)
      call check(error, code, 0)
      if (allocated(error)) return
      text = read_text(prefix//".summits.csv")
      call check(error, text(1:index(text, new_line("a")) - 1), "box_nm,n,density_per_um2,mean_height_nm,mean_radius_nm")
      if (allocated(error)) return
      call check(error, file_exists(prefix//".psd.svg") .and. file_exists(prefix//".fractal.csv"), "PSD outputs")
      if (allocated(error)) return
      call run_femcod([string_type("multiscale"), string_type("input/rough_selfaffine_32.deck"), string_type("--sizes"), &
         string_type("1,2,3"), string_type("--s"), string_type("5"), string_type("-o"), string_type(prefix), &
         string_type("--quiet"), string_type("--force")], code)
      call check(error, code, 0)
      if (allocated(error)) return
      text = read_text(prefix//".multiscale.csv")
      call check(error, text(1:index(text, new_line("a")) - 1), "s,constraint,scale,length_nm,load_nN,area_nm2,contacts")
      if (allocated(error)) return
      call remove_scratch(prefix//"_bad.summits.csv")
      call run_femcod([string_type("summits"), string_type("input/rough_selfaffine_32.deck"), string_type("--sizes"), &
         string_type("40"), string_type("-o"), string_type(prefix//"_bad"), string_type("--quiet")], code)
      call check(error, code, 2)
      if (allocated(error)) return
      call check(error, .not. file_exists(prefix//"_bad.summits.csv"), "no file on failure")
   end subroutine test_surface_commands
   !> `femcod multiscale` used the --estar default (200 GPa) whatever the deck said (issue
   !> 35). Now a deck's E* is the Hertz composite 1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2
   !> (Johnson, Contact Mechanics, eq. 4.22), computed here from the deck's numbers: the
   !> deck's areas equal those of its heights given as a file with --estar set to that
   !> value, bit for bit, and a deck with E1 = 70 instead of 200 GPa gives other areas.
   subroutine test_multiscale_estar(error)
      type(error_type), allocatable, intent(out) :: error
      type(contact_problem) :: deck
      type(status_type) :: st
      character(len=:), allocatable :: dir, heights
      character(len=32) :: estar_text
      character(len=25) :: buf
      real(dp) :: estar
      integer :: code, i, j
      dir = scratch_path("multiscale_estar")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call read_deck("input/rough_selfaffine_32.deck", deck, st)
      call check(error, all(deck%upper == 0), "the deck's upper surface is flat (its heights are the lower's)")
      if (allocated(error)) return
      heights = ""
      do i = 1, deck%np
         do j = 1, deck%np
            write(buf, '(es25.17)') deck%lower(i, j)
            heights = heights//buf
         end do
         heights = heights//new_line("a")
      end do
      open(newunit=i, file=dir//"/lower.txt", status="replace", action="write")
      write(i, '(a)', advance="no") heights
      close(i)
      estar = 1/((1 - deck%poisson(1)**2)/deck%young(1) + (1 - deck%poisson(2)**2)/deck%young(2))
      write(estar_text, '(es25.17)') estar
      call run_femcod([string_type("multiscale"), string_type("input/rough_selfaffine_32.deck"), &
         string_type("--sizes"), string_type("1,2,3"), string_type("-o"), string_type(dir//"/deck"), &
         string_type("--quiet")], code)
      call check(error, code, 0, "the deck")
      if (allocated(error)) return
      call run_femcod([string_type("multiscale"), string_type(dir//"/lower.txt"), string_type("--pixel"), &
         string_type("10"), string_type("--estar"), string_type(trim(adjustl(estar_text))), string_type("--sizes"), &
         string_type("1,2,3"), string_type("-o"), string_type(dir//"/file"), string_type("--quiet")], code)
      call check(error, code, 0, "the height file with --estar "//trim(adjustl(estar_text)))
      if (allocated(error)) return
      call check(error, read_text(dir//"/deck.multiscale.csv") == read_text(dir//"/file.multiscale.csv"), &
         "the deck's E* is "//trim(adjustl(estar_text))//" GPa: the same areas")
      if (allocated(error)) return
      deck%young(1) = 70
      call write_deck(dir//"/soft.deck", deck, st)
      call run_femcod([string_type("multiscale"), string_type(dir//"/soft.deck"), string_type("--sizes"), &
         string_type("1,2,3"), string_type("-o"), string_type(dir//"/soft"), string_type("--quiet")], code)
      call check(error, code, 0, "the soft deck")
      if (allocated(error)) return
      call check(error, read_text(dir//"/soft.multiscale.csv") /= read_text(dir//"/deck.multiscale.csv"), &
         "E1 = 70 GPa gives other areas than 200 GPa")
   end subroutine test_multiscale_estar
   !> On a 16 x 16 grid the PSD's fit range 4/L to 1/(4d) holds one frequency (4/L = 1/(4d))
   !> and the structure function's d to L/16 one lag, so no slope exists; femcod summits
   !> reported a profile dimension of 2.5 there (issue 35). Now the dimension fields are
   !> empty; on 64 x 64 (4/L to 1/(4d): frequencies 4..16 over L; lags 1..4 pixels) both
   !> are numbers.
   subroutine test_empty_fit(error)
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: dir, text
      integer :: code
      dir = scratch_path("empty_fit")
      call execute_command_line("rm -rf "//dir//" && mkdir -p "//dir)
      call run_femcod([string_type("mkdeck"), string_type("self-affine"), string_type("--np"), string_type("16"), &
         string_type("--pixel"), string_type("1"), string_type("-o"), string_type(dir//"/a.deck")], code)
      call run_femcod([string_type("summits"), string_type(dir//"/a.deck"), string_type("-o"), string_type(dir//"/a"), &
         string_type("--quiet")], code)
      call check(error, code, 0, "summits on 16 x 16")
      if (allocated(error)) return
      text = read_text(dir//"/a.fractal.csv")
      call check(error, contains_text(text, "psd,,,") .and. contains_text(text, "structure,,,"), &
         "no dimension on 16 x 16: "//text)
      if (allocated(error)) return
      call run_femcod([string_type("mkdeck"), string_type("self-affine"), string_type("--np"), string_type("64"), &
         string_type("--pixel"), string_type("1"), string_type("-o"), string_type(dir//"/b.deck")], code)
      call run_femcod([string_type("summits"), string_type(dir//"/b.deck"), string_type("-o"), string_type(dir//"/b"), &
         string_type("--quiet")], code)
      call check(error, code, 0, "summits on 64 x 64")
      if (allocated(error)) return
      text = read_text(dir//"/b.fractal.csv")
      call check(error, .not. (contains_text(text, "psd,,") .or. contains_text(text, "structure,,")), &
         "dimensions on 64 x 64: "//text)
   end subroutine test_empty_fit
end module test_studies
