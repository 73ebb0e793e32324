// SPDX-License-Identifier: MIT
// A small cache of imported dma-bufs (camera frames), keyed by the file each fd names
// (st_dev, st_ino) rather than by fd number, so that a recycled fd number of another
// buffer is imported afresh. Bounded: a camera pool cycles 4-8 buffers; beyond the
// capacity the least recently used import is handed back to be released.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "runtime/os.hpp"

namespace frappe::vc4::runtime {

template <class Entry>
class ImportCache {
public:
	static constexpr std::size_t kCapacity = 16;

	ImportCache() { slots_.reserve(kCapacity); } // no allocation once running

	// The import of `id`, marked as just used; nullptr when absent.
	Entry *find(const FileId &id)
	{
		for (Slot &s : slots_)
			if (s.id == id) {
				s.used = ++clock_;
				return &s.entry;
			}
		return nullptr;
	}

	// Adds an import; when full, first hands the least recently used to `release`.
	template <class Release>
	Entry &add(const FileId &id, Entry entry, Release &&release)
	{
		if (slots_.size() == kCapacity) {
			std::size_t oldest = 0;
			for (std::size_t i = 1; i < slots_.size(); ++i)
				if (slots_[i].used < slots_[oldest].used)
					oldest = i;
			release(slots_[oldest].entry);
			slots_.erase(slots_.begin() + static_cast<std::ptrdiff_t>(oldest));
		}
		slots_.push_back({id, entry, ++clock_});
		return slots_.back().entry;
	}

	template <class Release>
	void clear(Release &&release)
	{
		for (Slot &s : slots_)
			release(s.entry);
		slots_.clear();
	}

	template <class Fn>
	void forEach(Fn &&fn)
	{
		for (Slot &s : slots_)
			fn(s.entry);
	}
	template <class Fn>
	void forEach(Fn &&fn) const
	{
		for (const Slot &s : slots_)
			fn(s.entry);
	}

	std::size_t size() const { return slots_.size(); }

private:
	struct Slot {
		FileId id;
		Entry entry;
		uint64_t used = 0;
	};
	std::vector<Slot> slots_;
	uint64_t clock_ = 0;
};

} // namespace frappe::vc4::runtime
