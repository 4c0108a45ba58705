!> What every result file of a run names the same way: the CSV tables' columns, the maps
!> of a tangential step, the record of the run (run_info), the load groups' names, a
!> temporary file's final name, and the values several files derive alike (the plastic
!> count of a step, the area-load power law, the boundary and adhesion as text).
module femcod_result_schema
   use, intrinsic :: ieee_arithmetic, only: ieee_value, ieee_quiet_nan
   use femcod_kinds, only: dp
   use femcod_problem, only: contact_problem
   use femcod_strings, only: string_type, int_str
   use femcod_files, only: temporary_name
   use femcod_contact_result, only: contact_result
   use femcod_richardson, only: power_law_fit
   use femcod_shear_model, only: friction_coefficient
   implicit none
   private
   public :: run_info, FIGURES_AUTO_LIMIT, HISTORY_HEADER, LOADS_HEADER, CONTACTS_HEADER, FRICTION_COLUMNS, TANGENTIAL_COLUMNS, &
      PATCH_COLUMNS, TANGENTIAL_MAPS, TANGENTIAL_UNITS, result_name, step_plastic, area_fit, load_group, run_boundary, &
      has_adhesion

   !> The CSV files' header lines (the help prints them from here).
   character(len=*), parameter :: HISTORY_HEADER = &
      "step,contacts,load_nN,approach_nm,area_nm2,area_fraction,n_above_hardness,n_plastic"
   character(len=*), parameter :: LOADS_HEADER = "load_nN,approach_nm,contacts,area_nm2,area_fraction,"// &
      "max_pressure_GPa,n_above_hardness,n_plastic,plastic_volume_nm3,kappa"
   character(len=*), parameter :: CONTACTS_HEADER = "i,j,step,force_nN,pressure_GPa"
   !> The columns every loads file ends with: the contact patches, 4- and 8-connected
   !> (model/femcod_patches).
   character(len=*), parameter :: PATCH_COLUMNS = ",patches_4,patches_8"
   !> The columns the shear model adds to the history and loads files.
   character(len=*), parameter :: FRICTION_COLUMNS = ",friction_nN,friction_coefficient"
   !> The maps of a tangential step in each load group (and on the mesh).
   character(len=*), parameter :: TANGENTIAL_MAPS(4) = [character(len=7) :: "shear_x", "shear_y", "stick", "slip"]
   character(len=*), parameter :: TANGENTIAL_UNITS(4) = [character(len=3) :: "GPa", "GPa", "1", "1"]
   !> The columns a tangential step adds to the loads file.
   character(len=*), parameter :: TANGENTIAL_COLUMNS = ",tangential_force_nN,tangential_shift_nm,stick_contacts,"// &
      "stick_fraction"

   !> What the run was, for /run in the HDF5 file.
   !> With --figures auto (the default) the map figures of every state up to this many
   !> requested states, beyond it of the last reached one only (1001 loads wrote 17 MB of
   !> figures): at most 40 map files (2 to 4 a state).
   integer, parameter :: FIGURES_AUTO_LIMIT = 10

   type :: run_info
      character(len=:), allocatable :: version, solver, options
      !> Which states get their map figures (--figures): "all", "last", "none", or "auto"
      !> (unallocated too: all up to FIGURES_AUTO_LIMIT states, else the last).
      character(len=:), allocatable :: figures
      !> The lateral boundary, "free" or "periodic" (--boundary).
      character(len=:), allocatable :: boundary
      !> The adhesion law (--adhesion: "dugdale" or "exponential"; unallocated or "none":
      !> no adhesion), its work (J/m^2) and range (nm).
      character(len=:), allocatable :: adhesion
      real(dp) :: work = 0, range = 0
      !> With the shear model (--shear-strength, --shear-slope): true, and its tau0 (GPa),
      !> alpha (1) and cap (GPa; huge: none). Adds the friction columns and attributes.
      logical :: friction = .false.
      real(dp) :: shear_strength = 0, shear_slope = 0, shear_cap = huge(1.0_dp)
      !> With a tangential step (--tangential, --slip): true, its Coulomb coefficient, and
      !> Dundurs' beta of the materials (the coupling left out). Adds the tangential
      !> columns, attributes and maps.
      logical :: tangential = .false.
      real(dp) :: coulomb = 0, beta = 0
      !> A solver of the cg family (femcod run --solver cg, femcod-mpi): each state has
      !> the iteration's work (cg_* attributes) and the mean gap.
      logical :: cg = .false.
      !> The scales of the dimensionless area-load slope kappa = (A/A0) / (p/(E* h'_rms))
      !> of each state (p = F/A0 the nominal pressure): the rms slope h'_rms (1) of the
      !> composite surface at the pixel (model/femcod_scene's rms_slope of the initial
      !> gaps) and the composite modulus E* (GPa); 0: not known (kappa NaN).
      real(dp) :: rms_slope = 0, composite_modulus = 0
      !> What the scene left out, one line each.
      type(string_type), allocatable :: scene(:)
      !> What the run warns of (a requested state not reached, a tangential step without
      !> contact), one line each (femcod run prints them on standard error).
      type(string_type), allocatable :: warnings(:)
      !> The input files, one line each: the deck, or what each height file gave
      !> (format, channel, instrument, grid, scan and pixel size); each file's SHA-256;
      !> the fingerprint of the problem and options (a restart's check).
      type(string_type), allocatable :: inputs(:), digests(:)
      character(len=:), allocatable :: fingerprint
      !> The command as typed (femcod run ...), the machine, and when the run started
      !> and its results were written (ISO 8601 with the UTC offset).
      character(len=:), allocatable :: command_line, host, started, finished
      !> The OpenMP threads and how idle ones wait (femcod_process's wait_policy_text).
      integer :: threads = 0
      character(len=:), allocatable :: wait_policy
      !> Wall seconds of the parts of the run before the writing: reading the inputs,
      !> their digests, the maps of the reached loads (the solve is the result's own).
      real(dp) :: read_seconds = 0, digest_seconds = 0, maps_seconds = 0
   end type run_info

contains

   !> The result file a temporary name stands for (temporary_name appends ".part").
   function result_name(tmp) result(name)
      character(len=*), intent(in) :: tmp
      character(len=:), allocatable :: name
      integer :: k
      k = index(tmp, ".part", back=.true.)
      name = tmp
      if (k > 1) name = tmp(1:k - 1)
   end function result_name

   !> The pixels at the hardness after step k (0 without the plastic cap).
   pure integer function step_plastic(res, k)
      type(contact_result), intent(in) :: res
      integer, intent(in) :: k
      step_plastic = 0
      if (allocated(res%step_plastic)) then
         if (k <= size(res%step_plastic)) step_plastic = res%step_plastic(k)
      end if
   end function step_plastic

   !> area = prefactor * load^exponent, least squares in log-log over the steps with
   !> positive load; NaN for both when fewer than two (no fit: null in the summary file,
   !> where 0, 0 read as a fit).
   subroutine area_fit(deck, res, exponent, prefactor)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      real(dp), intent(out) :: exponent, prefactor
      logical, allocatable :: keep(:)
      exponent = ieee_value(exponent, ieee_quiet_nan)
      prefactor = exponent
      if (res%nsteps < 2) return
      keep = res%step_load(1:res%nsteps) > 0
      if (count(keep) < 2) return
      call power_law_fit(pack(res%step_load(1:res%nsteps), keep), &
         pack(res%step_contacts(1:res%nsteps)*deck%pixel**2, keep), exponent, prefactor)
   end subroutine area_fit

   !> The group of requested load k of n: /loads/001 ... (at least three digits, so
   !> that the names sort as numbers).
   function load_group(k, n) result(g)
      integer, intent(in) :: k, n
      character(len=:), allocatable :: g
      integer :: width
      width = max(3, len(int_str(n)))
      g = int_str(k)
      g = "/loads/"//repeat("0", width - len(g))//g
   end function load_group

   !> The run's boundary ("free" unless the caller says otherwise).
   pure function run_boundary(info) result(text)
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: text
      text = "free"
      if (allocated(info%boundary)) text = info%boundary
   end function run_boundary

   !> Whether the run had an adhesion law.
   pure logical function has_adhesion(info)
      type(run_info), intent(in) :: info
      has_adhesion = .false.
      if (allocated(info%adhesion)) has_adhesion = info%adhesion /= "none"
   end function has_adhesion
end module femcod_result_schema
