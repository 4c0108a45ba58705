!> Serialisation of a solver's state by a visitor: the state lists every field it must
!> keep, once, in `visit`; a writer visitor stores the fields, a reader visitor fills
!> them back in the same order. A new field is one line in the state's `visit`, never
!> an edit of the checkpoint writer and reader (io/femcod_checkpoint implements both
!> with HDF5). No I/O here.
!>
!> Arrays come in three kinds:
!> - `integer_array`, `real_array`: an allocatable stored whole (the reader allocates it);
!> - `integer_prefix`, `real_prefix`, `real_rows`: the leading n entries (rows) of an
!>   array the state has already allocated at its full size; the reader checks that
!>   the stored length is n;
!> - `real_triangle`: the upper triangle of a(1:n, 1:n), packed column by column.
!> `group` names a sub-object (a load state of the result, say) whose fields follow.
module femcod_state_visitor
   use femcod_kinds, only: dp, i8
   use femcod_status, only: status_type
   implicit none
   private
   public :: state_visitor, visitable

   !> What visits: a writer or a reader. `status` carries the first failure; every
   !> procedure returns at once when it holds an error.
   type, abstract :: state_visitor
      type(status_type) :: status
   contains
      procedure(visit_group), deferred :: group
      procedure(visit_integer), deferred :: integer_value
      procedure(visit_long), deferred :: long_value
      procedure(visit_real), deferred :: real_value
      procedure(visit_logical), deferred :: logical_value
      procedure(visit_integers), deferred :: integer_array
      procedure(visit_reals), deferred :: real_array
      procedure(visit_integer_prefix), deferred :: integer_prefix
      procedure(visit_real_prefix), deferred :: real_prefix
      procedure(visit_real_rows), deferred :: real_rows
      procedure(visit_real_triangle), deferred :: real_triangle
   end type state_visitor

   !> A state that can be visited: it calls the visitor once per field, in a fixed order.
   type, abstract :: visitable
   contains
      procedure(visit_state), deferred :: visit
   end type visitable

   abstract interface
      subroutine visit_state(self, visitor)
         import :: visitable, state_visitor
         class(visitable), intent(inout) :: self
         class(state_visitor), intent(inout) :: visitor
      end subroutine visit_state
      !> Enter the sub-object `name` (a path below the state's root, e.g. "result/state_2").
      subroutine visit_group(self, name)
         import :: state_visitor
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
      end subroutine visit_group
      subroutine visit_integer(self, name, value)
         import :: state_visitor
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         integer, intent(inout) :: value
      end subroutine visit_integer
      subroutine visit_long(self, name, value)
         import :: state_visitor, i8
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         integer(i8), intent(inout) :: value
      end subroutine visit_long
      subroutine visit_real(self, name, value)
         import :: state_visitor, dp
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         real(dp), intent(inout) :: value
      end subroutine visit_real
      subroutine visit_logical(self, name, value)
         import :: state_visitor
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         logical, intent(inout) :: value
      end subroutine visit_logical
      subroutine visit_integers(self, name, values)
         import :: state_visitor
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         integer, allocatable, intent(inout) :: values(:)
      end subroutine visit_integers
      subroutine visit_reals(self, name, values)
         import :: state_visitor, dp
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         real(dp), allocatable, intent(inout) :: values(:)
      end subroutine visit_reals
      subroutine visit_integer_prefix(self, name, values, n)
         import :: state_visitor
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         integer, intent(inout) :: values(:)
         integer, intent(in) :: n
      end subroutine visit_integer_prefix
      subroutine visit_real_prefix(self, name, values, n)
         import :: state_visitor, dp
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         real(dp), intent(inout) :: values(:)
         integer, intent(in) :: n
      end subroutine visit_real_prefix
      subroutine visit_real_rows(self, name, values, n)
         import :: state_visitor, dp
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         real(dp), intent(inout) :: values(:, :)
         integer, intent(in) :: n
      end subroutine visit_real_rows
      subroutine visit_real_triangle(self, name, values, n)
         import :: state_visitor, dp
         class(state_visitor), intent(inout) :: self
         character(len=*), intent(in) :: name
         real(dp), intent(inout) :: values(:, :)
         integer, intent(in) :: n
      end subroutine visit_real_triangle
   end interface
end module femcod_state_visitor
