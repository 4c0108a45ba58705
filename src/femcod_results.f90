!> Result files of a run (CSV), written under temporary names and renamed only when
!> all of them are complete, so a failed run leaves no partial result.
!>   PREFIX.history.csv   step,contacts,load_nN,approach_nm,area_nm2,area_fraction
!>   PREFIX.loads.csv     load_nN,approach_nm,contacts,area_nm2,area_fraction,max_pressure_GPa,n_above_hardness
!>   PREFIX.contacts.csv  i,j,step,force_nN,pressure_GPa
module femcod_results
   use femcod_kinds, only: dp
   use femcod_status, only: status_type, set_error, STATUS_IO
   use femcod_deck, only: deck_type, format_real
   use femcod_strings, only: int_str
   use femcod_files, only: atomic_rename, remove_file, temporary_name
   use femcod_contact_result, only: contact_result
   implicit none
   private
   public :: write_csv_results

contains

   !> Write the three CSV files for `prefix`. The loads file is written only when loads
   !> were requested.
   subroutine write_csv_results(prefix, deck, res, status)
      character(len=*), intent(in) :: prefix
      type(deck_type), intent(in) :: deck
      type(contact_result), intent(in) :: res
      type(status_type), intent(inout) :: status
      character(len=:), allocatable :: names(:), temps(:)
      integer :: unit, ios, k, nfiles
      real(dp) :: area_pixel, region
      logical :: with_loads
      area_pixel = deck%pixel**2
      region = deck%np**2*area_pixel
      with_loads = size(res%states) > 0
      nfiles = merge(3, 2, with_loads)
      allocate(character(len=len(prefix) + 14) :: names(3), temps(3))
      names(1) = prefix//".history.csv"
      names(2) = prefix//".contacts.csv"
      names(3) = prefix//".loads.csv"
      do k = 1, 3
         temps(k) = temporary_name(trim(names(k)))
      end do

      ios = 0
      open(newunit=unit, file=trim(temps(1)), status="replace", action="write", iostat=ios)
      if (ios /= 0) then
         call fail(1)
         return
      end if
      write(unit, '(a)', iostat=ios) "step,contacts,load_nN,approach_nm,area_nm2,area_fraction"
      do k = 1, res%nsteps
         write(unit, '(a)', iostat=ios) int_str(k)//","//int_str(res%step_contacts(k))//","// &
            format_real(res%step_load(k))//","//format_real(res%step_approach(k))//","// &
            format_real(res%step_contacts(k)*area_pixel)//","//format_real(res%step_contacts(k)*area_pixel/region)
      end do
      close(unit, iostat=ios)
      if (ios /= 0) then
         call fail(1)
         return
      end if

      open(newunit=unit, file=trim(temps(2)), status="replace", action="write", iostat=ios)
      if (ios /= 0) then
         call fail(2)
         return
      end if
      write(unit, '(a)', iostat=ios) "i,j,step,force_nN,pressure_GPa"
      do k = 1, size(res%contact_i)
         write(unit, '(a)', iostat=ios) int_str(res%contact_i(k))//","//int_str(res%contact_j(k))//","// &
            int_str(res%contact_step(k))//","//format_real(res%contact_force(k))//","// &
            format_real(res%contact_force(k)/area_pixel)
      end do
      close(unit, iostat=ios)
      if (ios /= 0) then
         call fail(2)
         return
      end if

      if (with_loads) then
         open(newunit=unit, file=trim(temps(3)), status="replace", action="write", iostat=ios)
         if (ios /= 0) then
            call fail(3)
            return
         end if
         write(unit, '(a)', iostat=ios) &
            "load_nN,approach_nm,contacts,area_nm2,area_fraction,max_pressure_GPa,n_above_hardness"
         do k = 1, size(res%states)
            if (.not. res%states(k)%reached) cycle
            associate(s => res%states(k))
               write(unit, '(a)', iostat=ios) format_real(s%load)//","//format_real(s%approach)//","// &
                  int_str(s%contacts)//","//format_real(s%contacts*area_pixel)//","// &
                  format_real(s%contacts*area_pixel/region)//","//format_real(s%max_pressure)//","// &
                  int_str(s%n_above_hardness)
            end associate
         end do
         close(unit, iostat=ios)
         if (ios /= 0) then
            call fail(3)
            return
         end if
      end if

      do k = 1, nfiles
         call atomic_rename(trim(temps(k)), trim(names(k)), status)
         if (status%code /= 0) then
            call cleanup()
            return
         end if
      end do
   contains
      subroutine fail(which)
         integer, intent(in) :: which
         call set_error(status, STATUS_IO, trim(names(which))//": cannot write (directory missing or not writable)")
         call cleanup()
      end subroutine fail
      subroutine cleanup()
         integer :: m
         do m = 1, 3
            call remove_file(trim(temps(m)))
         end do
      end subroutine cleanup
   end subroutine write_csv_results
end module femcod_results
