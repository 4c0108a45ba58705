!> One requested state's values (model/femcod_contact_result's state_values) as every
!> result names them, once for `femcod run`, femcod-mpi and the C and Python libraries:
!> the table of a state's fields (name with its units, value, how it is written), from
!> which come the state's entry in PREFIX.summary.json, the attributes of its load group
!> in PREFIX.h5 and the libraries' state values; and the row of PREFIX.loads.csv. Which
!> optional fields a run has (the cg family's work, the tangential step, the shear model,
!> adhesion) comes from its run_info (run_info_of: from the options).
module femcod_state_record
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use femcod_kinds, only: dp
   use femcod_status, only: status_type
   use femcod_strings, only: int_str, format_real, json_string, json_number
   use femcod_contact_result, only: state_values, cg_state_diagnostics
   use femcod_shear_model, only: shear_model, friction_coefficient
   use femcod_solver_options, only: contact_options, SOLVER_CG, BOUNDARY_PERIODIC, solver_name, boundary_name, law_name, &
      run_shear_model
   use femcod_problem, only: contact_problem
   use femcod_love, only: composite_modulus
   use femcod_scene, only: initial_gap_map, rms_slope
   use femcod_hdf5, only: h5_file, h5_attribute
   use femcod_result_schema, only: run_info, LOADS_HEADER, FRICTION_COLUMNS, TANGENTIAL_COLUMNS, PATCH_COLUMNS, &
      load_group, has_adhesion
   implicit none
   private
   public :: state_field, state_fields, FIELD_NUMBER, FIELD_COUNT, FIELD_FLAG, run_info_of, run_info_for
   public :: loads_csv_header, loads_csv_row, state_json, state_attributes

   !> How a field is written: a number, a count (an integer), a flag (true/false in JSON,
   !> 1/0 in HDF5 and the libraries).
   integer, parameter :: FIELD_NUMBER = 0, FIELD_COUNT = 1, FIELD_FLAG = 2

   !> One value of a state: its name (with its units), the value, how it is written.
   type :: state_field
      character(len=:), allocatable :: name
      real(dp) :: value = 0
      integer :: kind = FIELD_NUMBER
   end type state_field

contains

   !> The run record's columns for `options` (solver, boundary, adhesion, shear model,
   !> tangential step): femcod run's, femcod-mpi's and the libraries' one reading.
   pure function run_info_of(options) result(info)
      type(contact_options), intent(in) :: options
      type(run_info) :: info
      type(shear_model) :: shear
      info%solver = solver_name(options%solver)
      info%cg = options%solver == SOLVER_CG
      info%boundary = boundary_name(options%boundary)
      info%adhesion = law_name(options%adhesion)
      info%work = options%work
      info%range = options%range
      info%friction = options%shear
      info%tangential = options%tangential
      info%coulomb = options%friction
      if (options%shear) then
         shear = run_shear_model(options)
         info%shear_strength = shear%tau0
         info%shear_slope = shear%alpha
         info%shear_cap = shear%tau_max
      end if
   end function run_info_of

   !> The run record's columns for `options` on `problem`: run_info_of's, and the scales
   !> of kappa (the rms slope of the initial gaps, the composite modulus of the bodies).
   function run_info_for(problem, options) result(info)
      type(contact_problem), intent(in) :: problem
      type(contact_options), intent(in) :: options
      type(run_info) :: info
      info = run_info_of(options)
      info%composite_modulus = composite_modulus(problem%young(1:2), problem%poisson(1:2))
      if (allocated(problem%lower) .and. allocated(problem%upper)) info%rms_slope = &
         rms_slope(initial_gap_map(problem%lower, problem%upper), problem%pixel, options%boundary == BOUNDARY_PERIODIC)
   end function run_info_for

   !> The fields of a state on an NP x NP grid of pixel d (nm): the common ones, then the
   !> cg family's work (`work`), the tangential step's, the shear model's and the
   !> adhesion's where the run has them.
   function state_fields(v, pixel, np, info, work) result(f)
      type(state_values), intent(in) :: v
      real(dp), intent(in) :: pixel
      integer, intent(in) :: np
      type(run_info), intent(in) :: info
      type(cg_state_diagnostics), intent(in) :: work
      type(state_field), allocatable :: f(:)
      f = [field("load_nN", v%load), field("approach_nm", v%approach), count_of("contacts", v%contacts), &
         field("area_nm2", v%contacts*pixel**2), field("area_fraction", v%contacts*pixel**2/(real(np, dp)**2*pixel**2)), &
         field("max_pressure_GPa", v%max_pressure), count_of("n_above_hardness", v%n_above_hardness), &
         count_of("n_plastic", v%n_plastic), field("plastic_volume_nm3", v%plastic_volume), &
         field("kappa", kappa(v, pixel, info)), count_of("patches_4", v%patches_4), count_of("patches_8", v%patches_8)]
      if (info%cg) f = [f, count_of("cg_iterations", work%iterations), field("cg_residual", work%residual), &
         field("cg_penetration_nm", work%penetration), field("cg_contact_gap_nm", work%contact_gap), &
         field("cg_load_error", work%load_error), field("approach_error_bound_nm", work%approach_bound)]
      if (info%tangential) f = [f, field("tangential_force_nN", v%tangential_force(1)), &
         field("tangential_force_y_nN", v%tangential_force(2)), field("tangential_shift_nm", v%tangential_shift(1)), &
         field("tangential_shift_y_nm", v%tangential_shift(2)), count_of("stick_contacts", v%stick_contacts), &
         field("stick_area_nm2", v%stick_contacts*pixel**2), state_field("gross_sliding", merge(1, 0, v%sliding), &
         FIELD_FLAG), count_of("tangential_iterations", v%tangential_iterations), &
         field("tangential_residual", v%tangential_residual)]
      if (info%friction) f = [f, field("friction_nN", v%friction), &
         field("friction_coefficient", friction_coefficient(v%friction, v%load, v%contacts))]
      if (info%cg .or. has_adhesion(info)) f = [f, field("mean_gap_nm", v%mean_gap)]
      if (has_adhesion(info)) f = [f, count_of("attractive_pixels", v%attractive), &
         field("attractive_load_nN", v%attractive_load), count_of("jump", v%jump)]
   contains
      pure type(state_field) function field(name, value)
         character(len=*), intent(in) :: name
         real(dp), intent(in) :: value
         field = state_field(name, value, FIELD_NUMBER)
      end function field
      pure type(state_field) function count_of(name, n)
         character(len=*), intent(in) :: name
         integer, intent(in) :: n
         count_of = state_field(name, real(n, dp), FIELD_COUNT)
      end function count_of
   end function state_fields

   !> State k of n's entry in the summary's "loads" list: `{...}` with the load, whether it
   !> was reached and, if so, the state's fields (approach_error_bound_nm where there is a
   !> bound), its load group, and `detail` and `extra`, a program's own fields (each
   !> ", "-led or empty).
   function state_json(v, k, n, pixel, np, info, work, detail, extra) result(text)
      type(state_values), intent(in) :: v
      integer, intent(in) :: k, n, np
      real(dp), intent(in) :: pixel
      type(run_info), intent(in) :: info
      type(cg_state_diagnostics), intent(in) :: work
      character(len=*), intent(in) :: detail, extra
      character(len=:), allocatable :: text
      type(state_field), allocatable :: f(:)
      integer :: m
      text = '{"load_nN": '//json_number(v%load)//', "reached": '//trim(merge("true ", "false", v%reached))
      if (v%reached) then
         f = state_fields(v, pixel, np, info, work)
         do m = 2, size(f)
            if (f(m)%name == "approach_error_bound_nm" .and. f(m)%value < 0) cycle
            text = text//', "'//f(m)%name//'": '//json_value(f(m))
         end do
         text = text//', "hdf5_group": '//json_string(load_group(k, n))//detail//extra
      end if
      text = text//'}'
   contains
      function json_value(x) result(t)
         type(state_field), intent(in) :: x
         character(len=:), allocatable :: t
         select case (x%kind)
         case (FIELD_COUNT)
            t = int_str(nint(x%value))
         case (FIELD_FLAG)
            t = trim(merge("true ", "false", x%value /= 0))
         case default
            t = json_number(x%value)
         end select
      end function json_value
   end function state_json

   !> State k's fields as attributes of its load group `g` in PREFIX.h5, after its index.
   subroutine state_attributes(file, g, k, v, pixel, np, info, work, status)
      type(h5_file), intent(in) :: file
      character(len=*), intent(in) :: g
      integer, intent(in) :: k, np
      type(state_values), intent(in) :: v
      real(dp), intent(in) :: pixel
      type(run_info), intent(in) :: info
      type(cg_state_diagnostics), intent(in) :: work
      type(status_type), intent(inout) :: status
      type(state_field), allocatable :: f(:)
      integer :: m
      call h5_attribute(file, g, "index", k, status)
      f = state_fields(v, pixel, np, info, work)
      do m = 1, size(f)
         if (f(m)%kind == FIELD_NUMBER) then
            call h5_attribute(file, g, f(m)%name, f(m)%value, status)
         else
            call h5_attribute(file, g, f(m)%name, nint(f(m)%value), status)
         end if
      end do
   end subroutine state_attributes

   !> A state's dimensionless area-load slope kappa = (A/A0) / (p/(E* h'_rms)) =
   !> A E* h'_rms / F (A = contacts d^2 the pixel-counted area, F the load, nN; E* GPa);
   !> NaN at F <= 0 or without the run's slope and modulus.
   pure real(dp) function kappa(v, pixel, info)
      type(state_values), intent(in) :: v
      real(dp), intent(in) :: pixel
      type(run_info), intent(in) :: info
      kappa = ieee_value(kappa, ieee_quiet_nan)
      if (v%load > 0 .and. info%rms_slope > 0 .and. info%composite_modulus > 0) &
         kappa = v%contacts*pixel**2*info%composite_modulus*info%rms_slope/v%load
   end function kappa

   !> The header of PREFIX.loads.csv: the common columns, the shear model's and the
   !> tangential step's where the run has them, the patches.
   function loads_csv_header(info) result(text)
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: text
      text = LOADS_HEADER
      if (info%friction) text = text//FRICTION_COLUMNS
      if (info%tangential) text = text//TANGENTIAL_COLUMNS
      text = text//PATCH_COLUMNS
   end function loads_csv_header

   !> A state's row of PREFIX.loads.csv (no line end) on an NP x NP grid of pixel d (nm).
   function loads_csv_row(v, pixel, np, info) result(text)
      type(state_values), intent(in) :: v
      real(dp), intent(in) :: pixel
      integer, intent(in) :: np
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: text
      real(dp) :: area_pixel
      area_pixel = pixel**2
      text = format_real(v%load)//","//format_real(v%approach)//","//int_str(v%contacts)//","// &
         format_real(v%contacts*area_pixel)//","//format_real(v%contacts*area_pixel/(real(np, dp)**2*area_pixel))// &
         ","//format_real(v%max_pressure)//","//int_str(v%n_above_hardness)//","//int_str(v%n_plastic)//","// &
         format_real(v%plastic_volume)//","//format_real(kappa(v, pixel, info))
      if (info%friction) text = text//","//format_real(v%friction)//","// &
         format_real(friction_coefficient(v%friction, v%load, v%contacts))
      if (info%tangential) then
         ! A state without contact had no tangential step.
         if (allocated(v%stick)) then
            text = text//","//format_real(v%tangential_force(1))//","//format_real(v%tangential_shift(1))//","// &
               int_str(v%stick_contacts)//","//format_real(real(v%stick_contacts, dp)/max(v%contacts, 1))
         else
            text = text//",0,0,0,nan"
         end if
      end if
      text = text//","//int_str(v%patches_4)//","//int_str(v%patches_8)
   end function loads_csv_row
end module femcod_state_record
