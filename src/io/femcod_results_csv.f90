!> A run's CSV tables as text: PREFIX.history.csv (one row per step), PREFIX.loads.csv
!> (one row per requested state) and PREFIX.contacts.csv (the contacts of the last state);
!> numbers in their shortest exact decimal form.
module femcod_results_csv
   use femcod_kinds, only: dp, i8
   use femcod_problem, only: contact_problem
   use femcod_strings, only: int_str, text_builder, add_line, built_text, format_real, format_reals, integer_text
   use femcod_contact_result, only: contact_result
   use femcod_state_record, only: loads_csv_header, loads_csv_row
   use femcod_shear_model, only: friction_coefficient
   use femcod_result_schema, only: run_info, HISTORY_HEADER, CONTACTS_HEADER, FRICTION_COLUMNS, step_plastic
   implicit none
   private
   public :: history_csv, contacts_csv, loads_csv

contains

   !> PREFIX.history.csv: one row per step; with `friction`, the shear model's columns.
   function history_csv(deck, res, friction) result(text)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      logical, intent(in) :: friction
      character(len=:), allocatable :: text
      type(text_builder) :: b
      integer :: k
      real(dp) :: area_pixel, region
      area_pixel = deck%pixel**2
      region = deck%np**2*area_pixel
      call add_line(b, HISTORY_HEADER//trim(merge(FRICTION_COLUMNS, repeat(" ", len(FRICTION_COLUMNS)), friction)))
      do k = 1, res%nsteps
         call add_line(b, int_str(k)//","//int_str(res%step_contacts(k))//","// &
            format_real(res%step_load(k))//","//format_real(res%step_approach(k))//","// &
            format_real(res%step_contacts(k)*area_pixel)//","//format_real(res%step_contacts(k)*area_pixel/region)// &
            ","//int_str(res%step_above_hardness(k))//","//int_str(step_plastic(res, k))// &
            friction_fields(friction, res%step_friction(k), res%step_load(k), res%step_contacts(k)))
      end do
      text = built_text(b)
   end function history_csv

   !> ",F_t,mu" for the friction columns (F_t nN at load F nN); "" without them.
   function friction_fields(friction, force, load, contacts) result(text)
      logical, intent(in) :: friction
      real(dp), intent(in) :: force, load
      integer, intent(in) :: contacts
      character(len=:), allocatable :: text
      text = ""
      if (friction) text = ","//format_real(force)//","//format_real(friction_coefficient(force, load, contacts))
   end function friction_fields

   !> PREFIX.contacts.csv: the contact pixels and their forces at the reported load.
   function contacts_csv(deck, res) result(text)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      character(len=:), allocatable :: text
      character(len=*), parameter :: header = CONTACTS_HEADER
      character(len=24), allocatable :: force(:), pressure(:)
      integer, allocatable :: nf(:), np(:)
      integer(i8), allocatable :: ends(:)
      character(len=20) :: ti, tj, ts
      integer :: k, ni, nj, ns
      integer(i8) :: at
      call format_reals(res%contact_force, force, nf)
      call format_reals(res%contact_force/deck%pixel**2, pressure, np)
      ! Each row's end in the text from the lengths of its numbers, then every row
      ! written at its place, in parallel (fixed-length buffers only: see
      ! shortest_decimal).
      allocate(ends(0:size(res%contact_i)))
      ends(0) = len(header) + 1
      do k = 1, size(res%contact_i)
         ends(k) = ends(k - 1) + digits_of(res%contact_i(k)) + digits_of(res%contact_j(k)) + &
            digits_of(res%contact_step(k)) + nf(k) + np(k) + 5
      end do
      allocate(character(len=ends(size(res%contact_i))) :: text)
      text(1:len(header) + 1) = header//new_line("a")
      !$omp parallel do private(k, ti, tj, ts, ni, nj, ns, at) schedule(static)
      do k = 1, size(res%contact_i)
         call integer_text(int(res%contact_i(k), i8), ti, ni)
         call integer_text(int(res%contact_j(k), i8), tj, nj)
         call integer_text(int(res%contact_step(k), i8), ts, ns)
         at = ends(k - 1)
         text(at + 1:ends(k)) = ti(1:ni)//","//tj(1:nj)//","//ts(1:ns)//","//force(k)(1:nf(k))//","// &
            pressure(k)(1:np(k))//new_line("a")
      end do
      !$omp end parallel do
   contains
      !> The characters of the integer n in decimal.
      pure integer function digits_of(n)
         integer, intent(in) :: n
         integer :: m
         digits_of = merge(2, 1, n < 0)
         m = abs(n)
         do while (m >= 10)
            m = m/10
            digits_of = digits_of + 1
         end do
      end function digits_of
   end function contacts_csv

   !> PREFIX.loads.csv: the states at the requested loads that were reached
   !> (io/femcod_state_record's rows).
   function loads_csv(deck, res, info) result(text)
      type(contact_problem), intent(in) :: deck
      type(contact_result), intent(in) :: res
      type(run_info), intent(in) :: info
      character(len=:), allocatable :: text
      type(text_builder) :: b
      integer :: k
      call add_line(b, loads_csv_header(info))
      do k = 1, size(res%states)
         if (res%states(k)%reached) call add_line(b, loads_csv_row(res%states(k)%state_values, deck%pixel, deck%np, info))
      end do
      text = built_text(b)
   end function loads_csv
end module femcod_results_csv
