// SPDX-License-Identifier: Apache-2.0
/*
 * gcov_flush.so: preloaded in the kernel test's guest (tests/kernel/run.sh, guest.sh) so that a
 * --coverage caracarad that dies of a fatal signal still writes its line counters.
 *
 * The daemon's fatal-signal handler does its emergency stop (the kill output through
 * GpioLine::set_in_signal_handler, the zero orders), then restores the default action and calls
 * raise(). gcov writes its counters at exit, which such a process never reaches, so the
 * handler's code would read as never executed. This raise() first calls gcov's own exit hook
 * (__gcov_exit, a local symbol of the executable, found in its .symtab), then the real raise():
 * the process still ends by its signal. A program without that symbol is not affected.
 */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <elf.h>
#include <fcntl.h>
#include <link.h>
#include <stdint.h>
#include <string.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

static int first_object(struct dl_phdr_info *info, size_t size, void *data)
{
	(void)size;
	*(uintptr_t *)data = info->dlpi_addr; /* the executable comes first: its load bias */
	return 1;
}

static uintptr_t symbol_in_exe(const char *name)
{
	struct stat st;
	uintptr_t found = 0;
	int fd = open("/proc/self/exe", O_RDONLY | O_CLOEXEC);

	if (fd < 0)
		return 0;
	if (fstat(fd, &st) < 0 || (size_t)st.st_size < sizeof(ElfW(Ehdr))) {
		close(fd);
		return 0;
	}
	const unsigned char *m = mmap(NULL, (size_t)st.st_size, PROT_READ, MAP_PRIVATE, fd, 0);
	close(fd);
	if (m == MAP_FAILED)
		return 0;
	const ElfW(Ehdr) *eh = (const ElfW(Ehdr) *)m;
	const ElfW(Shdr) *sh = (const ElfW(Shdr) *)(m + eh->e_shoff);
	for (unsigned i = 0; i < eh->e_shnum && !found; i++) {
		if (sh[i].sh_type != SHT_SYMTAB)
			continue;
		const ElfW(Sym) *sym = (const ElfW(Sym) *)(m + sh[i].sh_offset);
		const char *str = (const char *)(m + sh[sh[i].sh_link].sh_offset);
		for (size_t k = 0; k < sh[i].sh_size / sizeof(*sym); k++) {
			if (ELF64_ST_TYPE(sym[k].st_info) == STT_FUNC && sym[k].st_value &&
			    strcmp(str + sym[k].st_name, name) == 0) {
				uintptr_t bias = 0;

				dl_iterate_phdr(first_object, &bias);
				found = bias + sym[k].st_value;
				break;
			}
		}
	}
	munmap((void *)m, (size_t)st.st_size);
	return found;
}

int raise(int sig)
{
	int (*real)(int) = (int (*)(int))dlsym(RTLD_NEXT, "raise");
	uintptr_t gcov_exit = symbol_in_exe("__gcov_exit");

	if (gcov_exit)
		((void (*)(void))gcov_exit)();
	return real(sig);
}
