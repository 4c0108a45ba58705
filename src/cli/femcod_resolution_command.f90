!> `femcod resolution`: the resolution study of the thesis' section 4.5 on a deck or height
!> files (studies/femcod_resolution_study solves the levels), its table and figures.
module femcod_resolution_command
   use, intrinsic :: iso_fortran_env, only: output_unit, error_unit
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_USAGE
   use femcod_problem, only: contact_problem
   use femcod_shear_model, only: friction_coefficient
   use femcod_strings, only: string_type, int_str, sig_str, text_builder, add_line, built_text, format_real
   use femcod_generate, only: scene_spec
   use femcod_heights, only: is_height_file
   use femcod_files, only: default_prefix, file_part
   use femcod_results, only: write_file_set
   use femcod_svg, only: svg_series, svg_multi_plot, add_series
   use femcod_clock, only: wall_clock
   use femcod_resolution_study, only: resolution_level, solve_level, extrapolate_levels, check_levels
   use femcod_observer, only: solver_observer
   use femcod_help, only: help_requested, print_lines
   use femcod_options, only: option_spec, parsed_options, parse_options, option_help, scene_options, flag_option, &
      real_option, text_option, choice_option, integer_list_option, get_option, option_given, refuse_options
   use femcod_studies, only: fitted_exponent, surface_scene, study_deck, check_outputs, study_json
   implicit none
   private
   public :: resolution_command, resolution_table

   !> Progress of the solve inside a level: a line on standard error every 10 s.
   type, extends(solver_observer) :: level_observer
      logical :: quiet = .false.
      real(dp) :: last_report = 0
   contains
      procedure :: progress => level_progress
   end type level_observer

contains

   !> The options of `femcod resolution`; "heights" ones apply to a height file only.
   function resolution_table() result(table)
      type(option_spec), allocatable :: table(:)
      table = [ &
         text_option("--output", "PREFIX", "output prefix (default: the input's name)", alias="-o"), &
         integer_list_option("--levels", "L1,...", "NP of each level (default: NP, NP/2, NP/4, NP/8 down to 8 "// &
            "pixels)", lower=1), &
         choice_option("--method", "subsample|average", "odd/odd pixels (default) or 2 x 2 means"), &
         real_option("--hardness", "H", "GPa, for the pixels above the hardness per step (default 11, polysilicon)", &
            lower=0.0_dp, closed="()"), &
         real_option("--shear-strength", "TAU0", "friction from the pressures as in femcod run: tau = TAU0 + "// &
            "ALPHA p (GPa) on each contact pixel; adds friction_nN and friction_coefficient to PREFIX.resolution.csv "// &
            "and the coefficient at a common load to the summary", lower=0.0_dp), &
         real_option("--shear-slope", "ALPHA", "the shear strength's pressure coefficient (1, default 0)", &
            lower=0.0_dp), &
         flag_option("--force", "replace existing result files"), &
         flag_option("--quiet", "no summary, no progress lines", alias="-q"), &
         scene_options("heights")]
   end function resolution_table

   subroutine resolution_help()
      write(output_unit, '(a)') &
         "usage: femcod resolution DECK [--levels 512,256,128,64] [--method subsample|average] [-o PREFIX]", &
         "                         [--hardness H] [--shear-strength TAU0] [--shear-slope ALPHA] [--force] [--quiet]", &
         "       femcod resolution FILE --pixel D [--young E] [--poisson NU] [--maxcont M] [--remove-plane]", &
         "                         [options as above]", &
         "", &
         "The resolution study of the thesis, section 4.5: the surfaces down-sampled by keeping the odd/odd", &
         "pixels (subsample, default) or by averaging 2 x 2 blocks (average), the pixel size doubling at each", &
         "halving and MAXCONT scaled with the pixel count; the event-exact contact history at every level,", &
         "and beside it the estimates of Figs. 4.17, 4.18 and 4.21. FILE: heights (nm) as an ASCII matrix or", &
         "FILE.h5:/dataset on an elastic lower body (default 200 GPa, 0.25) against a rigid flat.", ""
      call print_lines(option_help(resolution_table(), ""))
      write(output_unit, '(a)') "with a height file (FILE --pixel D):"
      call print_lines(option_help(resolution_table(), "heights"))
      write(output_unit, '(a)') "", &
         "outputs: PREFIX.resolution.csv  np,method,load_nN,approach_nm,area_nm2 (one row per step and level;", &
         "                                with the shear model also friction_nN,friction_coefficient)", &
         "         PREFIX.powerlaw.csv    np,exponent,prefactor (area = prefactor * load^exponent over the run)", &
         "         PREFIX.estimates.csv   np,model,load_nN,area_nm2 with model coupled (femcod), uncoupled", &
         "                                (rigid substrate, independent voxels of the single-pixel compliance,", &
         "                                at femcod's approaches), mccool (Greenwood-Williamson from the RMS", &
         "                                height, slope and curvature at that resolution, at femcod's loads),", &
         "                                richardson (rate-1 extrapolation from the next coarser level; np is", &
         "                                the finer one)", &
         "         PREFIX.hardness.csv    np,step,area_fraction,contacts,n_above_hardness,fraction_above_hardness", &
         "         PREFIX.hardness_capped.csv  np,step,load_nN,area_fraction,contacts,n_plastic,fraction_plastic:", &
         "                                the finest level again with pressures capped at H (--plastic)", &
         "         PREFIX.load_displacement.svg, .area_displacement.svg (Fig. 4.17), .area_pressure.svg,", &
         "         .richardson.svg (Fig. 4.18), .hardness.svg (Fig. 4.21)", &
         "exit codes: 0 ok, 2 usage, 3 bad input, 4 numerical failure, 5 I/O"
   end subroutine resolution_help

   !> `femcod resolution`.
   subroutine resolution_command(args, code)
      type(string_type), intent(in) :: args(:)
      integer, intent(out) :: code
      type(contact_problem) :: deck
      type(status_type) :: status
      type(resolution_level), allocatable :: levels(:)
      type(string_type), allocatable :: names(:), texts(:)
      type(parsed_options) :: parsed
      type(scene_spec) :: spec
      type(level_observer) :: observer
      integer, allocatable :: nps(:)
      character(len=:), allocatable :: input, prefix, method
      real(dp) :: hardness, t0, t1, shear(2)
      integer :: k, n
      logical :: force, quiet, friction
      code = 0
      if (help_requested(args)) then
         call resolution_help()
         return
      end if
      call parse_options(resolution_table(), args, parsed, status)
      if (status%code == 0) then
         if (size(parsed%positional) == 0) call set_error(status, STATUS_USAGE, "no deck or height file given")
         if (size(parsed%positional) > 1) call set_error(status, STATUS_USAGE, "one input only (found '"// &
            parsed%positional(1)%s//"' and '"//parsed%positional(2)%s//"')")
      end if
      if (status%code == 0) call refuse_options(parsed, merge("heights", "       ", option_given(parsed, "--pixel") .or. &
         is_height_file(parsed%positional(1)%s)), &
         "heights=to a height file (FILE --pixel D), not to a deck", status)
      if (status%code /= 0) then
         call usage(status%message)
         return
      end if
      input = parsed%positional(1)%s
      prefix = ""
      method = "subsample"
      hardness = 11
      force = .false.
      quiet = .false.
      allocate(nps(0))
      call get_option(parsed, "--output", prefix)
      call get_option(parsed, "--method", method)
      call get_option(parsed, "--levels", nps)
      call get_option(parsed, "--hardness", hardness)
      friction = option_given(parsed, "--shear-strength") .or. option_given(parsed, "--shear-slope")
      shear = 0
      call get_option(parsed, "--shear-strength", shear(1))
      call get_option(parsed, "--shear-slope", shear(2))
      call get_option(parsed, "--force", force)
      call get_option(parsed, "--quiet", quiet)
      if (prefix == "") prefix = default_prefix(file_part(input))
      names = [string_type(prefix//".resolution.csv"), string_type(prefix//".powerlaw.csv"), &
         string_type(prefix//".estimates.csv"), string_type(prefix//".hardness.csv"), &
         string_type(prefix//".load_displacement.svg"), string_type(prefix//".area_displacement.svg"), &
         string_type(prefix//".area_pressure.svg"), string_type(prefix//".richardson.svg"), &
         string_type(prefix//".hardness.svg"), string_type(prefix//".hardness_capped.csv"), &
         string_type(prefix//".resolution.json")]
      ! The outputs are checked before the input is read: an input is never an output.
      call check_outputs(names, input, force, status)
      if (status%code /= 0) then
         call fail(status)
         return
      end if
      call surface_scene(parsed, input, spec)
      call study_deck(input, spec, deck, status)
      if (status%code /= 0) then
         call fail(status)
         return
      end if
      if (size(nps) == 0) then
         n = deck%np
         do while (n >= 8 .and. size(nps) < 4)
            nps = [nps, n]
            if (method == "average") then
               n = n/2
            else
               n = (n + 1)/2
            end if
         end do
         if (size(nps) == 0) nps = [deck%np]
      end if
      call check_levels(deck%np, nps, method, status)
      if (status%code /= 0) then
         call fail(status)
         return
      end if
      observer%quiet = quiet
      allocate(levels(size(nps)))
      do k = 1, size(nps)
         call wall_clock(t0)
         observer%last_report = 0
         ! The finest level also with the pressures capped at H (Fig. 4.21's capped curve).
         if (friction) then
            call solve_level(deck, nps(k), method, hardness, levels(k), status, observer, &
               capped=nps(k) == maxval(nps), shear=shear)
         else
            call solve_level(deck, nps(k), method, hardness, levels(k), status, observer, &
               capped=nps(k) == maxval(nps))
         end if
         if (status%code /= 0) then
            status%message = "level NP = "//int_str(nps(k))//": "//status%message
            call fail(status)
            return
         end if
         call wall_clock(t1)
         if (.not. quiet) then
            associate(r => levels(k)%res)
               write(output_unit, '(a)') "femcod resolution: NP = "//int_str(levels(k)%np)//" ("//method//", pixel "// &
                  sig_str(levels(k)%pixel, 6)//" nm): "//int_str(r%nsteps)//" steps, "// &
                  int_str(r%step_contacts(r%nsteps))//" contacts, load "//sig_str(r%step_load(r%nsteps), 6)// &
                  " nN, area ~ load^"//sig_str(levels(k)%exponent, 4)//", "//sig_str(t1 - t0, 3)//" s"
            end associate
         end if
      end do
      call extrapolate_levels(levels)
      texts = resolution_texts(levels, method, deck%np*deck%pixel, friction)
      texts = [texts, string_type(study_json("resolution", args, input, prefix, names, texts))]
      call write_file_set(names, texts, status)
      if (status%code /= 0) then
         call fail(status)
         return
      end if
      if (.not. quiet) then
         do k = 1, size(levels)
            if (levels(k)%coarser_np > 0) write(output_unit, '(a)') "  Richardson "//int_str(levels(k)%coarser_np)// &
               " & "//int_str(levels(k)%np)//": area ~ load^"//sig_str(fitted_exponent(levels(k)%richardson_load, &
               levels(k)%richardson_area), 4)
            write(output_unit, '(a)') "  McCool NP = "//int_str(levels(k)%np)//": area ~ load^"// &
               sig_str(fitted_exponent(levels(k)%res%step_load(1:levels(k)%res%nsteps), levels(k)%mccool_area), 4)// &
               " (eta "//sig_str(levels(k)%mccool%density, 4)//" /nm^2, R "//sig_str(levels(k)%mccool%radius, 4)// &
               " nm, sigma_s "//sig_str(levels(k)%mccool%sigma, 4)//" nm)"
         end do
         if (friction) call print_common_friction(levels, shear(2))
         write(output_unit, '(a)') "  wrote "//prefix//".resolution.csv, .powerlaw.csv, .estimates.csv, .hardness.csv, "// &
            ".hardness_capped.csv, .resolution.json (the tables) and 5 SVG figures"
      end if
   contains
      subroutine usage(message)
         character(len=*), intent(in) :: message
         write(error_unit, '(a)') "femcod resolution: "//message//" (femcod resolution --help)"
         code = STATUS_USAGE
      end subroutine usage
      subroutine fail(st)
         type(status_type), intent(in) :: st
         write(error_unit, '(a)') "femcod resolution: "//st%message
         code = st%code
      end subroutine fail
   end subroutine resolution_command

   !> The friction coefficient of every level at the largest load L all of them reached
   !> (nN), from the history row that ends the step holding L: within that step the
   !> contacts are the row's and their forces linear in the load, so F_t(L) = F_t(row) -
   !> alpha (F(row) - L), exact where no pixel crosses the shear cap within the step.
   subroutine print_common_friction(levels, alpha)
      type(resolution_level), intent(in) :: levels(:)
      real(dp), intent(in) :: alpha
      real(dp) :: common, ft
      integer :: k, i
      common = huge(1.0_dp)
      do k = 1, size(levels)
         common = min(common, levels(k)%res%step_load(levels(k)%res%nsteps))
      end do
      write(output_unit, '(a)') "  friction coefficient at "//sig_str(common, 6)//" nN (the largest load every "// &
         "level reached):"
      do k = 1, size(levels)
         associate(r => levels(k)%res)
            i = 1
            do while (r%step_load(i) < common .and. i < r%nsteps)
               i = i + 1
            end do
            ft = r%step_friction(i) - alpha*(r%step_load(i) - common)
            write(output_unit, '(a)') "    NP = "//int_str(levels(k)%np)//" (pixel "//sig_str(levels(k)%pixel, 4)// &
               " nm): "//sig_str(ft/common, 6)
         end associate
      end do
   end subroutine print_common_friction

   !> The CSV and SVG texts of a resolution study, in the order of the names above; with
   !> `friction`, the shear model's columns in the first.
   function resolution_texts(levels, method, side, friction) result(texts)
      type(resolution_level), intent(in) :: levels(:)
      character(len=*), intent(in) :: method
      real(dp), intent(in) :: side
      logical, intent(in) :: friction
      type(string_type) :: texts(10)
      type(text_builder) :: b(5)
      type(svg_series), allocatable :: s1(:), s2(:), s3(:), s4(:), s5(:)
      integer :: k, i, n
      real(dp) :: a0, px2
      character(len=:), allocatable :: npk
      a0 = side**2
      call add_line(b(1), "np,method,load_nN,approach_nm,area_nm2"// &
         trim(merge(",friction_nN,friction_coefficient", "                                 ", friction)))
      call add_line(b(2), "np,exponent,prefactor")
      call add_line(b(3), "np,model,load_nN,area_nm2")
      call add_line(b(4), "np,step,area_fraction,contacts,n_above_hardness,fraction_above_hardness")
      call add_line(b(5), "np,step,load_nN,area_fraction,contacts,n_plastic,fraction_plastic")
      allocate(s1(0), s2(0), s3(0), s4(0), s5(0))
      do k = 1, size(levels)
         associate(r => levels(k)%res)
            n = r%nsteps
            npk = int_str(levels(k)%np)
            px2 = levels(k)%pixel**2
            do i = 1, n
               call add_line(b(1), npk//","//method//","//format_real(r%step_load(i))//","// &
                  format_real(r%step_approach(i))//","//format_real(r%step_contacts(i)*px2)//friction_text(i))
            end do
            call add_line(b(2), npk//","//format_real(levels(k)%exponent)//","//format_real(levels(k)%prefactor))
            do i = 1, n
               call add_line(b(3), npk//",coupled,"//format_real(r%step_load(i))//","//format_real(r%step_contacts(i)*px2))
            end do
            do i = 1, n
               call add_line(b(3), npk//",uncoupled,"//format_real(levels(k)%uncoupled_load(i))//","// &
                  format_real(levels(k)%uncoupled_area(i)))
            end do
            do i = 1, n
               call add_line(b(3), npk//",mccool,"//format_real(r%step_load(i))//","//format_real(levels(k)%mccool_area(i)))
            end do
            do i = 1, size(levels(k)%richardson_load)
               call add_line(b(3), npk//",richardson,"//format_real(levels(k)%richardson_load(i))//","// &
                  format_real(levels(k)%richardson_area(i)))
            end do
            do i = 1, n
               call add_line(b(4), npk//","//int_str(i)//","//format_real(r%step_contacts(i)*px2/a0)//","// &
                  int_str(r%step_contacts(i))//","//int_str(r%step_above_hardness(i))//","// &
                  format_real(real(r%step_above_hardness(i), dp)/max(r%step_contacts(i), 1)))
            end do
            ! Figures: loads in mN and areas in um^2 against displacement (Fig. 4.17),
            ! area fraction against apparent pressure in MPa (Fig. 4.18), the share of
            ! contacts above the hardness against the area fraction in % (Fig. 4.21).
            call add_series(s1, npk//" x "//npk, r%step_approach(1:n), r%step_load(1:n)*1.0e-6_dp)
            call add_series(s2, npk//" x "//npk, r%step_approach(1:n), r%step_contacts(1:n)*px2*1.0e-6_dp)
            call add_series(s3, "femcod "//npk//" x "//npk, r%step_load(1:n)/a0*1.0e3_dp, &
               r%step_contacts(1:n)*px2/a0, dashed=.true.)
            call add_series(s3, "McCool "//npk//" x "//npk, r%step_load(1:n)/a0*1.0e3_dp, &
               levels(k)%mccool_area/a0, markers=.false.)
            call add_series(s4, "femcod "//npk//" x "//npk, r%step_load(1:n)/a0*1.0e3_dp, &
               r%step_contacts(1:n)*px2/a0, dashed=.true.)
            if (size(levels(k)%richardson_load) > 0) call add_series(s4, "extrapolation "// &
               int_str(levels(k)%coarser_np)//" & "//npk, levels(k)%richardson_load/a0*1.0e3_dp, &
               levels(k)%richardson_area/a0, markers=.false.)
            call add_series(s5, npk//" x "//npk, r%step_contacts(1:n)*px2/a0*100, &
               100*real(r%step_above_hardness(1:n), dp)/max(r%step_contacts(1:n), 1))
            if (levels(k)%has_capped) then
               associate(c => levels(k)%capped, nc => levels(k)%capped%nsteps)
                  do i = 1, nc
                     call add_line(b(5), npk//","//int_str(i)//","//format_real(c%step_load(i))//","// &
                        format_real(c%step_contacts(i)*px2/a0)//","//int_str(c%step_contacts(i))//","// &
                        int_str(c%step_plastic(i))//","// &
                        format_real(real(c%step_plastic(i), dp)/max(c%step_contacts(i), 1)))
                  end do
                  call add_series(s5, npk//" x "//npk//", capped at H", c%step_contacts(1:nc)*px2/a0*100, &
                     100*real(c%step_plastic(1:nc), dp)/max(c%step_contacts(1:nc), 1), dashed=.true.)
               end associate
            end if
         end associate
      end do
      ! The uncoupled model of the finest level (dashed, as in Fig. 4.17).
      k = maxloc(levels%np, 1)
      n = levels(k)%res%nsteps
      call add_series(s1, "no coupling ("//int_str(levels(k)%np)//")", levels(k)%res%step_approach(1:n), &
         levels(k)%uncoupled_load*1.0e-6_dp, dashed=.true., markers=.false.)
      call add_series(s2, "no coupling ("//int_str(levels(k)%np)//")", levels(k)%res%step_approach(1:n), &
         levels(k)%uncoupled_area*1.0e-6_dp, dashed=.true., markers=.false.)
      ! In Fig. 4.18a only up to the largest load femcod reached, so that the axes fit.
      associate(keep => levels(k)%uncoupled_load <= levels(k)%res%step_load(n))
         call add_series(s3, "no coupling ("//int_str(levels(k)%np)//")", &
            pack(levels(k)%uncoupled_load, keep)/a0*1.0e3_dp, pack(levels(k)%uncoupled_area, keep)/a0, &
            dashed=.true., markers=.false.)
      end associate
      do k = 1, 4
         texts(k)%s = built_text(b(k))
      end do
      texts(5)%s = svg_multi_plot("load against displacement (thesis Fig. 4.17a)", "displacement (nm)", &
         "contact load (mN)", s1, .false., .false.)
      texts(6)%s = svg_multi_plot("area against displacement (thesis Fig. 4.17b)", "displacement (nm)", &
         "contact area (um^2)", s2, .false., .false.)
      texts(7)%s = svg_multi_plot("area fraction against pressure: femcod and McCool (Fig. 4.18a)", &
         "apparent pressure (MPa)", "fraction of the area in contact", s3, .false., .false.)
      texts(8)%s = svg_multi_plot("Richardson extrapolation, rate 1 (thesis Fig. 4.18b)", "apparent pressure (MPa)", &
         "fraction of the area in contact", s4, .false., .false.)
      texts(9)%s = svg_multi_plot("contacts above the hardness (thesis Fig. 4.21), and at it when capped", &
         "contact area / total surface area (%)", "contacts with p > H, or at H when capped (%)", s5, .false., .false.)
      texts(10)%s = built_text(b(5))
   contains
      !> ",F_t,mu" of row i of level k's history with the friction columns; "" without.
      function friction_text(i) result(t)
         integer, intent(in) :: i
         character(len=:), allocatable :: t
         t = ""
         if (friction) t = ","//format_real(levels(k)%res%step_friction(i))//","// &
            format_real(friction_coefficient(levels(k)%res%step_friction(i), levels(k)%res%step_load(i), &
            levels(k)%res%step_contacts(i)))
      end function friction_text
   end function resolution_texts

   !> Progress within a level's solve, every 10 s on standard error.
   subroutine level_progress(self, step, contacts, load, elapsed)
      class(level_observer), intent(inout) :: self
      integer, intent(in) :: step, contacts
      real(dp), intent(in) :: load, elapsed
      if (self%quiet .or. elapsed - self%last_report < 10) return
      self%last_report = elapsed
      write(error_unit, '(a)') "femcod resolution: event "//int_str(step)//", "//int_str(contacts)//" contacts, load "// &
         sig_str(load, 5)//" nN, "//sig_str(elapsed, 3)//" s"
      flush(error_unit)
   end subroutine level_progress
end module femcod_resolution_command
