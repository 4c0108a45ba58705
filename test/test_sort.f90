!> Core algorithms: the stable merge sort of the gaps (Appendix B), and SHA-256.
module test_sort
   use femcod_kinds, only: dp
   use femcod_sort, only: merge_sort_index
   use femcod_random, only: random_stream, seed_stream, uniform
   use femcod_sha256, only: sha256_hex, file_sha256_hex, file_digest, file_sha256_start, file_sha256_finish
   use testdrive, only: new_unittest, unittest_type, error_type, check
   implicit none
   private
   public :: collect_sort

contains

   subroutine collect_sort(testsuite)
      type(unittest_type), allocatable, intent(out) :: testsuite(:)
      testsuite = [ &
         new_unittest("ties keep row-wise order", test_ties), &
         new_unittest("sorted and reversed input", test_sorted_reversed), &
         new_unittest("random input against insertion sort", test_random), &
         new_unittest("SHA-256 of the FIPS 180-4 examples", test_sha256), &
         new_unittest("SHA-256 of files read in blocks, also on a thread: FIPS 180-4's million a, 3 MiB + 5", &
            test_sha256_file) &
         ]
   end subroutine collect_sort

   subroutine test_ties(error)
      type(error_type), allocatable, intent(out) :: error
      integer :: order(9)
      call merge_sort_index([2.0_dp, 0.0_dp, 1.0_dp, 0.0_dp, 2.0_dp, 1.0_dp, 0.0_dp, 1.0_dp, 2.0_dp], order)
      ! By hand: the zeros at 2, 4, 7, the ones at 3, 6, 8, the twos at 1, 5, 9.
      call check(error, all(order == [2, 4, 7, 3, 6, 8, 1, 5, 9]), "stable order of ties")
   end subroutine test_ties

   subroutine test_sorted_reversed(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 1000
      real(dp) :: v(n)
      integer :: order(n), i
      v = [(real(i, dp), i = 1, n)]
      call merge_sort_index(v, order)
      call check(error, all(order == [(i, i = 1, n)]), "sorted input keeps the identity")
      if (allocated(error)) return
      v = [(real(n - i, dp), i = 1, n)]
      call merge_sort_index(v, order)
      call check(error, all(order == [(n + 1 - i, i = 1, n)]), "reversed input is reversed")
      if (allocated(error)) return
      call merge_sort_index([5.0_dp], order(1:1))
      call check(error, order(1), 1, "a single value")
   end subroutine test_sorted_reversed

   subroutine test_random(error)
      type(error_type), allocatable, intent(out) :: error
      integer, parameter :: n = 777
      real(dp) :: v(n), u
      integer :: order(n), ref(n), i, j, key
      type(random_stream) :: stream
      call seed_stream(stream, 7)
      do i = 1, n
         call uniform(stream, u)
         v(i) = real(int(50*u), dp)   ! many ties
      end do
      call merge_sort_index(v, order)
      ! Reference: stable insertion sort.
      ref = [(i, i = 1, n)]
      do i = 2, n
         key = ref(i)
         j = i - 1
         do while (j >= 1)
            if (v(ref(j)) <= v(key)) exit
            ref(j + 1) = ref(j)
            j = j - 1
         end do
         ref(j + 1) = key
      end do
      call check(error, all(order == ref), "merge sort equals a stable insertion sort")
   end subroutine test_random

   !> The example digests of FIPS 180-4 (NIST's examples document): the empty string,
   !> "abc", and the 448-bit message of two blocks; a million "a" (padding crossing
   !> many blocks).
   subroutine test_sha256(error)
      type(error_type), allocatable, intent(out) :: error
      call check(error, sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855", "empty")
      if (allocated(error)) return
      call check(error, sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad", "abc")
      if (allocated(error)) return
      call check(error, sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"), &
         "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1", "two blocks")
      if (allocated(error)) return
      call check(error, sha256_hex(repeat("a", 1000000)), &
         "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0", "a million a")
   end subroutine test_sha256

   !> The digest of a file read in 1 MiB blocks: a file of a million "a" has FIPS 180-4's
   !> digest; a file of 3 MiB + 5 bytes (four blocks, the last of 5 bytes) the digest of
   !> the same bytes hashed whole; a missing file gives "". The same through a digest
   !> taken on a thread of its own (file_sha256_start, as femcod run takes it while it
   !> reads the deck), which is collected once: a second collection gives "".
   subroutine test_sha256_file(error)
      use test_support, only: scratch_path
      type(error_type), allocatable, intent(out) :: error
      character(len=:), allocatable :: path, bytes
      type(file_digest) :: digest, missing
      integer :: unit, k
      path = scratch_path("sha256-million-a")
      open(newunit=unit, file=path, access="stream", form="unformatted", status="replace")
      write(unit) repeat("a", 1000000)
      close(unit)
      call check(error, file_sha256_hex(path), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0", &
         "a million a")
      if (allocated(error)) return
      call file_sha256_start(path, digest)
      call check(error, file_sha256_finish(digest), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0", &
         "a million a, on a thread")
      if (allocated(error)) return
      call check(error, file_sha256_finish(digest), "", "a digest collected twice")
      if (allocated(error)) return
      allocate(character(len=3*1048576 + 5) :: bytes)
      do k = 1, len(bytes)
         bytes(k:k) = achar(mod(k*7 + k/1000, 256))
      end do
      open(newunit=unit, file=path, access="stream", form="unformatted", status="replace")
      write(unit) bytes
      close(unit)
      call check(error, file_sha256_hex(path), sha256_hex(bytes), "3 MiB + 5 bytes")
      if (allocated(error)) return
      call check(error, file_sha256_hex(path//".missing"), "", "a missing file")
      if (allocated(error)) return
      call file_sha256_start(path, digest)
      call file_sha256_start(path//".missing", missing)
      call check(error, file_sha256_finish(digest), sha256_hex(bytes), "3 MiB + 5 bytes, on a thread")
      if (allocated(error)) return
      call check(error, file_sha256_finish(missing), "", "a missing file, on a thread")
   end subroutine test_sha256_file
end module test_sort
