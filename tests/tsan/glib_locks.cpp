// SPDX-License-Identifier: MIT
// For the ThreadSanitizer build only: GLib's locks made visible to it.
//
// GLib's GMutex, GRecMutex and GCond are futexes inside libglib, which is not
// instrumented, so ThreadSanitizer sees none of the ordering they give:
// every field a GStreamer object guards with GST_OBJECT_LOCK (the element's
// properties, for one) would be reported as a race between the application
// thread and the streaming thread. Defined in the test program, these
// functions come before libglib's in symbol lookup, for GStreamer's calls
// too; each calls GLib's and tells ThreadSanitizer that the lock was taken
// or released, so what it reports is about Frappe's code.
#include <dlfcn.h>

#include <glib.h>
#include <sanitizer/tsan_interface.h>

namespace {

template<typename F>
F real(const char *name)
{
	return reinterpret_cast<F>(dlsym(RTLD_NEXT, name));
}

} // namespace

extern "C" {

void g_mutex_lock(GMutex *mutex)
{
	static const auto fn = real<void (*)(GMutex *)>("g_mutex_lock");
	fn(mutex);
	__tsan_acquire(mutex);
}

gboolean g_mutex_trylock(GMutex *mutex)
{
	static const auto fn = real<gboolean (*)(GMutex *)>("g_mutex_trylock");
	const gboolean taken = fn(mutex);
	if (taken)
		__tsan_acquire(mutex);
	return taken;
}

void g_mutex_unlock(GMutex *mutex)
{
	static const auto fn = real<void (*)(GMutex *)>("g_mutex_unlock");
	__tsan_release(mutex);
	fn(mutex);
}

void g_rec_mutex_lock(GRecMutex *mutex)
{
	static const auto fn = real<void (*)(GRecMutex *)>("g_rec_mutex_lock");
	fn(mutex);
	__tsan_acquire(mutex);
}

gboolean g_rec_mutex_trylock(GRecMutex *mutex)
{
	static const auto fn = real<gboolean (*)(GRecMutex *)>("g_rec_mutex_trylock");
	const gboolean taken = fn(mutex);
	if (taken)
		__tsan_acquire(mutex);
	return taken;
}

void g_rec_mutex_unlock(GRecMutex *mutex)
{
	static const auto fn = real<void (*)(GRecMutex *)>("g_rec_mutex_unlock");
	__tsan_release(mutex);
	fn(mutex);
}

/* A wait releases the mutex and takes it again. */
void g_cond_wait(GCond *cond, GMutex *mutex)
{
	static const auto fn = real<void (*)(GCond *, GMutex *)>("g_cond_wait");
	__tsan_release(mutex);
	fn(cond, mutex);
	__tsan_acquire(mutex);
}

gboolean g_cond_wait_until(GCond *cond, GMutex *mutex, gint64 end_time)
{
	static const auto fn = real<gboolean (*)(GCond *, GMutex *, gint64)>("g_cond_wait_until");
	__tsan_release(mutex);
	const gboolean signalled = fn(cond, mutex, end_time);
	__tsan_acquire(mutex);
	return signalled;
}

} // extern "C"
