!> SHA-256 (FIPS 180-4) of a byte string, as 64 lower-case hex digits: the provenance of
!> the input files in the run record, and the fingerprint that tells whether existing
!> results belong to the same inputs and options. The digest is OpenSSL's
!> (femcod_digest.c); the test suite checks it against the FIPS 180-4 examples.
module femcod_sha256
   use, intrinsic :: iso_c_binding, only: c_char, c_size_t, c_int, c_signed_char, c_null_char, c_ptr, c_null_ptr, &
      c_associated
   implicit none
   private
   public :: sha256_hex, file_sha256_hex, file_digest, file_sha256_start, file_sha256_finish

   !> A file's digest under way on a thread of its own (file_sha256_start), to be
   !> collected once by file_sha256_finish.
   type :: file_digest
      private
      type(c_ptr) :: job = c_null_ptr
      character(len=:), allocatable :: path
   end type file_digest

   interface
      !> femcod_digest.c: the 32-byte digest of n bytes; 0 on success.
      function c_sha256(data, n, digest) bind(c, name="femcod_sha256_digest") result(failed)
         import :: c_char, c_size_t, c_int, c_signed_char
         character(kind=c_char), intent(in) :: data(*)
         integer(c_size_t), value :: n
         integer(c_signed_char), intent(out) :: digest(32)
         integer(c_int) :: failed
      end function c_sha256
      !> femcod_digest.c: the 32-byte digest of a file, read in blocks; 0 on success.
      function c_sha256_file(path, digest) bind(c, name="femcod_sha256_file") result(failed)
         import :: c_char, c_int, c_signed_char
         character(kind=c_char), intent(in) :: path(*)
         integer(c_signed_char), intent(out) :: digest(32)
         integer(c_int) :: failed
      end function c_sha256_file
      !> femcod_digest.c: start a file's digest on a thread; the job, or NULL.
      function c_sha256_file_start(path) bind(c, name="femcod_sha256_file_start") result(job)
         import :: c_char, c_ptr
         character(kind=c_char), intent(in) :: path(*)
         type(c_ptr) :: job
      end function c_sha256_file_start
      !> femcod_digest.c: wait for a job's digest and free the job; 0 on success.
      function c_sha256_file_finish(job, digest) bind(c, name="femcod_sha256_file_finish") result(failed)
         import :: c_ptr, c_int, c_signed_char
         type(c_ptr), value :: job
         integer(c_signed_char), intent(out) :: digest(32)
         integer(c_int) :: failed
      end function c_sha256_file_finish
   end interface

contains

   !> The digest of `bytes` ("" when libcrypto fails, which it does only without memory).
   function sha256_hex(bytes) result(hex)
      character(len=*), intent(in) :: bytes
      character(len=64) :: hex
      character(kind=c_char, len=1) :: empty(1)
      integer(c_signed_char) :: digest(32)
      hex = ""
      if (len(bytes) == 0) then
         empty = c_char_"x"
         if (c_sha256(empty, 0_c_size_t, digest) /= 0) return
      else
         if (c_sha256(bytes, int(len(bytes), c_size_t), digest) /= 0) return
      end if
      hex = hex_of(digest)
   end function sha256_hex

   !> The digest of the file at `path`, read in blocks (the whole file is never held);
   !> "" when it cannot be read.
   function file_sha256_hex(path) result(hex)
      character(len=*), intent(in) :: path
      character(len=64) :: hex
      integer(c_signed_char) :: digest(32)
      hex = ""
      if (c_sha256_file(path//c_null_char, digest) /= 0) return
      hex = hex_of(digest)
   end function file_sha256_hex

   !> Start the digest of the file at `path` on a thread of its own, so that it is taken
   !> while the caller reads the file (where no thread can be started, file_sha256_finish
   !> takes it then).
   subroutine file_sha256_start(path, digest)
      character(len=*), intent(in) :: path
      type(file_digest), intent(out) :: digest
      digest%path = path
      digest%job = c_sha256_file_start(path//c_null_char)
   end subroutine file_sha256_start

   !> The digest started by file_sha256_start, as file_sha256_hex gives it ("" when the
   !> file cannot be read, and for a digest already collected: each is collected once).
   function file_sha256_finish(digest) result(hex)
      type(file_digest), intent(inout) :: digest
      character(len=64) :: hex
      integer(c_signed_char) :: bytes(32)
      hex = ""
      if (c_associated(digest%job)) then
         if (c_sha256_file_finish(digest%job, bytes) == 0) hex = hex_of(bytes)
         digest%job = c_null_ptr
      else if (allocated(digest%path)) then
         hex = file_sha256_hex(digest%path)
      end if
      if (allocated(digest%path)) deallocate(digest%path)
   end function file_sha256_finish

   !> 32 bytes as 64 lower-case hex digits.
   pure function hex_of(digest) result(hex)
      integer(c_signed_char), intent(in) :: digest(32)
      character(len=64) :: hex
      character(len=16), parameter :: digits = "0123456789abcdef"
      integer :: j, b
      do j = 1, 32
         b = iand(int(digest(j)), 255)
         hex(2*j - 1:2*j) = digits(b/16 + 1:b/16 + 1)//digits(mod(b, 16) + 1:mod(b, 16) + 1)
      end do
   end function hex_of
end module femcod_sha256
