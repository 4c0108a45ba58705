!> Checkpoint files (PREFIX.ckpt.h5) of the incremental solver: written atomically
!> (temporary name, then rename), so a run killed at any moment leaves either the
!> previous checkpoint or the new one, never a partial file. A checkpoint holds the
!> whole deck and the options that shape the history, and is refused for any other.
!>
!> Layout: /deck (label, NP, pixel, MAXCONT, young, poisson; lower, upper),
!> /options (max_contacts, loads, tie_tolerance, hardness, final_check),
!> /state (step, n, total, approach, phi, pix, cstep, ftot, ld, factor (the upper
!> triangle packed by columns), y, x, cache_pixel, cache_l, cache_w, predicted,
!> since_refill, last_neval, heap_key, heap_item),
!> /history (contacts, load, approach, seconds), /states/<k> (the requested loads
!> reached so far), /counters.
module femcod_checkpoint
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_BAD_INPUT
   use femcod_problem, only: contact_problem
   use femcod_strings, only: int_str, format_real
   use femcod_files, only: atomic_rename, remove_file, temporary_name
   use femcod_contact_result, only: contact_options, solver_state
   use femcod_hdf5, only: h5_file, h5_create, h5_open, h5_close, h5_group, h5_write, h5_read, h5_attribute, &
      h5_read_string_attribute, h5_exists
   use femcod_about, only: FEMCOD_VERSION
   implicit none
   private
   public :: write_checkpoint, read_checkpoint

   !> Marks a file as a femcod checkpoint (attribute /format).
   character(len=*), parameter :: FORMAT_TAG = "femcod checkpoint 3"

contains

   !> Store `state` for `deck` and `options` in `path`, atomically.
   subroutine write_checkpoint(path, deck, options, state, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(in) :: deck
      type(contact_options), intent(in) :: options
      type(solver_state), intent(in) :: state
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      character(len=:), allocatable :: tmp, g
      integer :: k, m
      if (status%code /= 0) return
      tmp = temporary_name(path)
      m = state%res%nsteps
      call h5_create(tmp, file, status)
      file%path = path
      call h5_attribute(file, "/", "format", FORMAT_TAG, status)
      call h5_attribute(file, "/", "femcod_version", FEMCOD_VERSION, status)
      call h5_group(file, "/deck", status)
      call h5_attribute(file, "/deck", "label", deck%label, status)
      call h5_write(file, "/deck/NP", deck%np, "1", status)
      call h5_write(file, "/deck/pixel", deck%pixel, "nm", status)
      call h5_write(file, "/deck/MAXCONT", deck%maxcont, "1", status)
      call h5_write(file, "/deck/young", deck%young, "GPa", status)
      call h5_write(file, "/deck/poisson", deck%poisson, "1", status)
      call h5_write(file, "/deck/lower", deck%lower, "nm", status)
      call h5_write(file, "/deck/upper", deck%upper, "nm", status)
      call h5_group(file, "/options", status)
      call h5_write(file, "/options/max_contacts", options%max_contacts, "1", status)
      call h5_write(file, "/options/loads", options%loads, "nN", status)
      call h5_write(file, "/options/tie_tolerance", options%tie_tolerance, "1", status)
      call h5_write(file, "/options/hardness", options%hardness, "GPa", status)
      call h5_write(file, "/options/final_check", merge(1, 0, options%final_check), "1", status)
      call h5_group(file, "/state", status)
      call h5_write(file, "/state/step", state%step, "1", status)
      call h5_write(file, "/state/n", state%n, "1", status)
      call h5_write(file, "/state/total", state%total, "nN", status)
      call h5_write(file, "/state/approach", state%approach, "nm", status)
      call h5_write(file, "/state/phi", state%phi, "nm", status)
      call h5_write(file, "/state/pix", state%pix, "1", status)
      call h5_write(file, "/state/cstep", state%cstep, "1", status)
      call h5_write(file, "/state/ftot", state%ftot, "nN", status)
      call h5_write(file, "/state/ld", state%ld, "1", status)
      call h5_write(file, "/state/factor", state%factor, "(nm/nN)^0.5", status)
      call h5_write(file, "/state/y", state%y, "(nN/nm)^0.5", status)
      call h5_write(file, "/state/x", state%x, "nN/nm", status)
      call h5_write(file, "/state/cache_pixel", state%cache_pixel, "1", status)
      call h5_write(file, "/state/cache_l", state%cache_l, "(nm/nN)^0.5", status)
      call h5_write(file, "/state/cache_w", state%cache_w, "1", status)
      call h5_write(file, "/state/predicted", state%predicted, "nN", status)
      call h5_write(file, "/state/since_refill", state%since_refill, "1", status)
      call h5_write(file, "/state/last_neval", state%last_neval, "1", status)
      call h5_write(file, "/state/heap_key", state%heap_key, "nm", status)
      call h5_write(file, "/state/heap_item", state%heap_item, "1", status)
      call h5_group(file, "/history", status)
      call h5_write(file, "/history/contacts", state%res%step_contacts(1:m), "1", status)
      call h5_write(file, "/history/above_hardness", state%res%step_above_hardness(1:m), "1", status)
      call h5_write(file, "/history/load", state%res%step_load(1:m), "nN", status)
      call h5_write(file, "/history/approach", state%res%step_approach(1:m), "nm", status)
      call h5_write(file, "/history/seconds", state%res%step_seconds(1:m), "s", status)
      call h5_group(file, "/states", status)
      do k = 1, size(state%res%states)
         if (.not. state%res%states(k)%reached) cycle
         g = "/states/"//int_str(k)
         associate(s => state%res%states(k))
            call h5_group(file, g, status)
            call h5_write(file, g//"/load", s%load, "nN", status)
            call h5_write(file, g//"/approach", s%approach, "nm", status)
            call h5_write(file, g//"/contacts", s%contacts, "1", status)
            call h5_write(file, g//"/max_pressure", s%max_pressure, "GPa", status)
            call h5_write(file, g//"/n_above_hardness", s%n_above_hardness, "1", status)
            call h5_write(file, g//"/i", s%i, "1", status)
            call h5_write(file, g//"/j", s%j, "1", status)
            call h5_write(file, g//"/force", s%force, "nN", status)
         end associate
      end do
      call h5_group(file, "/counters", status)
      call h5_write(file, "/counters/missed_during_run", state%res%missed_during_run, "1", status)
      call h5_write(file, "/counters/releases", state%res%releases, "1", status)
      call h5_write(file, "/counters/evaluations", real(state%res%evaluations, dp), "1", status)
      call h5_close(file, status)
      if (status%code /= 0) then
         call remove_file(tmp)
         return
      end if
      call atomic_rename(tmp, path, status)
   end subroutine write_checkpoint

   !> Read the state stored in `path`, refusing it (STATUS_BAD_INPUT) unless it was
   !> written for exactly this deck and these options.
   subroutine read_checkpoint(path, deck, options, state, status)
      character(len=*), intent(in) :: path
      type(contact_problem), intent(in) :: deck
      type(contact_options), intent(in) :: options
      type(solver_state), intent(out) :: state
      type(status_type), intent(inout) :: status
      type(h5_file) :: file
      character(len=:), allocatable :: tag, label, g
      real(dp), allocatable :: r1(:), r2(:, :)
      real(dp) :: r
      integer :: i, k, m, final_check
      integer, parameter :: bad = STATUS_BAD_INPUT
      if (status%code /= 0) return
      call h5_open(path, file, status, bad)
      call h5_read_string_attribute(file, "/", "format", len(FORMAT_TAG), tag, status, bad)
      if (status%code /= 0) then
         call h5_close(file, status)
         status%message = path//": not a femcod checkpoint (truncated or corrupted; delete it, or run without "// &
            "--restart)"
         return
      end if
      if (tag /= FORMAT_TAG) then
         call refuse("not a femcod checkpoint of this version (format '"//tag//"')")
         return
      end if
      ! The deck: everything must match exactly.
      call h5_read_string_attribute(file, "/deck", "label", max(len(deck%label), 1) + 1, label, status, bad)
      call h5_read(file, "/deck/NP", i, status, bad)
      if (status%code /= 0) return
      if (i /= deck%np) then
         call refuse("written for a deck with NP = "//int_str(i)//", this deck has NP = "//int_str(deck%np))
         return
      end if
      if (label /= deck%label) then
         call refuse("written for the deck '"//label//"', not '"//deck%label//"'")
         return
      end if
      call h5_read(file, "/deck/pixel", r, status, bad)
      if (status%code == 0 .and. r /= deck%pixel) then
         call refuse("pixel size "//format_real(r)//" nm differs from the deck's "//format_real(deck%pixel))
         return
      end if
      call h5_read(file, "/deck/MAXCONT", i, status, bad)
      if (status%code == 0 .and. i /= deck%maxcont) then
         call refuse("MAXCONT "//int_str(i)//" differs from the deck's "//int_str(deck%maxcont))
         return
      end if
      call h5_read(file, "/deck/young", r1, status, bad)
      if (status%code == 0 .and. .not. same(r1, deck%young)) then
         call refuse("Young's moduli differ from the deck's")
         return
      end if
      call h5_read(file, "/deck/poisson", r1, status, bad)
      if (status%code == 0 .and. .not. same(r1, deck%poisson)) then
         call refuse("Poisson's ratios differ from the deck's")
         return
      end if
      call h5_read(file, "/deck/lower", r2, status, bad)
      if (status%code == 0 .and. .not. same2(r2, deck%lower)) then
         call refuse("the lower surface's heights differ from the deck's")
         return
      end if
      call h5_read(file, "/deck/upper", r2, status, bad)
      if (status%code == 0 .and. .not. same2(r2, deck%upper)) then
         call refuse("the upper surface's heights differ from the deck's")
         return
      end if
      ! The options that shape the history.
      call h5_read(file, "/options/max_contacts", i, status, bad)
      if (status%code == 0 .and. i /= options%max_contacts) then
         call refuse("--max-contacts "//int_str(i)//" there, "//int_str(options%max_contacts)//" here")
         return
      end if
      call h5_read(file, "/options/loads", r1, status, bad)
      if (status%code == 0 .and. .not. same(r1, options%loads)) then
         call refuse("written with other --loads")
         return
      end if
      call h5_read(file, "/options/tie_tolerance", r, status, bad)
      if (status%code == 0 .and. r /= options%tie_tolerance) then
         call refuse("written with another tie tolerance")
         return
      end if
      call h5_read(file, "/options/hardness", r, status, bad)
      if (status%code == 0 .and. r /= options%hardness) then
         call refuse("written with --hardness "//format_real(r))
         return
      end if
      call h5_read(file, "/options/final_check", final_check, status, bad)
      if (status%code == 0 .and. (final_check == 1 .neqv. options%final_check)) then
         call refuse("written with another --no-final-check setting")
         return
      end if
      ! The state.
      call h5_read(file, "/state/step", state%step, status, bad)
      call h5_read(file, "/state/n", state%n, status, bad)
      call h5_read(file, "/state/total", state%total, status, bad)
      call h5_read(file, "/state/approach", state%approach, status, bad)
      call h5_read(file, "/state/phi", state%phi, status, bad)
      call h5_read(file, "/state/pix", state%pix, status, bad)
      call h5_read(file, "/state/cstep", state%cstep, status, bad)
      call h5_read(file, "/state/ftot", state%ftot, status, bad)
      call h5_read(file, "/state/ld", state%ld, status, bad)
      call h5_read(file, "/state/factor", state%factor, status, bad)
      call h5_read(file, "/state/y", state%y, status, bad)
      call h5_read(file, "/state/x", state%x, status, bad)
      call h5_read(file, "/state/cache_pixel", state%cache_pixel, status, bad)
      call h5_read(file, "/state/cache_l", r2, status, bad)
      state%cache_l = r2
      call h5_read(file, "/state/cache_w", r2, status, bad)
      state%cache_w = r2
      call h5_read(file, "/state/predicted", state%predicted, status, bad)
      call h5_read(file, "/state/since_refill", state%since_refill, status, bad)
      call h5_read(file, "/state/last_neval", state%last_neval, status, bad)
      call h5_read(file, "/state/heap_key", state%heap_key, status, bad)
      call h5_read(file, "/state/heap_item", state%heap_item, status, bad)
      call h5_read(file, "/history/contacts", state%res%step_contacts, status, bad)
      call h5_read(file, "/history/above_hardness", state%res%step_above_hardness, status, bad)
      call h5_read(file, "/history/load", state%res%step_load, status, bad)
      call h5_read(file, "/history/approach", state%res%step_approach, status, bad)
      call h5_read(file, "/history/seconds", state%res%step_seconds, status, bad)
      if (status%code /= 0) then
         call h5_close(file, status)
         return
      end if
      m = size(state%res%step_load)
      state%res%nsteps = m
      if (size(state%res%step_contacts) /= m .or. size(state%res%step_approach) /= m .or. &
         size(state%res%step_above_hardness) /= m .or. &
         size(state%res%step_seconds) /= m .or. m /= state%step .or. size(state%cstep) /= state%n .or. &
         size(state%ftot) /= state%n .or. state%n < 1 .or. state%n > deck%maxcont .or. &
         size(state%pix) /= state%n .or. size(state%y) /= state%n .or. size(state%x) /= state%n .or. &
         size(state%cache_l, 1) /= state%n .or. size(state%cache_w, 1) /= state%n .or. &
         size(state%heap_key) /= size(state%heap_item) .or. any(state%pix < 1) .or. &
         any(state%pix > deck%np**2) .or. any(state%heap_item < 1) .or. any(state%heap_item > deck%np**2) .or. &
         any(state%cache_pixel < 0) .or. any(state%cache_pixel > deck%np**2)) then
         call refuse("its state is inconsistent (corrupted)")
         return
      end if
      allocate(state%res%states(size(options%loads)))
      state%res%states%load = options%loads
      do k = 1, size(options%loads)
         g = "/states/"//int_str(k)
         if (.not. h5_exists(file, g)) cycle
         associate(s => state%res%states(k))
            s%reached = .true.
            call h5_read(file, g//"/load", s%load, status, bad)
            call h5_read(file, g//"/approach", s%approach, status, bad)
            call h5_read(file, g//"/contacts", s%contacts, status, bad)
            call h5_read(file, g//"/max_pressure", s%max_pressure, status, bad)
            call h5_read(file, g//"/n_above_hardness", s%n_above_hardness, status, bad)
            call h5_read(file, g//"/i", s%i, status, bad)
            call h5_read(file, g//"/j", s%j, status, bad)
            call h5_read(file, g//"/force", s%force, status, bad)
         end associate
      end do
      call h5_read(file, "/counters/missed_during_run", state%res%missed_during_run, status, bad)
      call h5_read(file, "/counters/releases", state%res%releases, status, bad)
      call h5_read(file, "/counters/evaluations", r, status, bad)
      state%res%evaluations = nint(r, kind(state%res%evaluations))
      call h5_close(file, status)
   contains
      subroutine refuse(why)
         character(len=*), intent(in) :: why
         type(status_type) :: ignore
         call h5_close(file, ignore)
         call set_error(status, bad, path//": checkpoint refused: "//why// &
            " (delete it, or run without --restart)")
      end subroutine refuse
      pure logical function same(a, b)
         real(dp), intent(in) :: a(:), b(:)
         same = size(a) == size(b)
         if (same) same = all(a == b)
      end function same
      pure logical function same2(a, b)
         real(dp), intent(in) :: a(:, :), b(:, :)
         same2 = all(shape(a) == shape(b))
         if (same2) same2 = all(a == b)
      end function same2
   end subroutine read_checkpoint
end module femcod_checkpoint
